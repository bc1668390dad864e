//! Histories: block-averaging standard errors on AR(1) series with known variance of the mean,
//! CSV tables with units written atomically, sampling every k steps.

mod support;

use homogenise::averaging::{block_average, window_average, MIN_BLOCKS};
use homogenise::history::{Sampler, SamplerConfig};
use homogenise::table::{Column, Table};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use support::v;

/// Stationary AR(1) `x_t = μ + φ (x_{t−1} − μ) + ε_t`, `ε ~ N(0, 1)`.
fn ar1(seed: u64, n: usize, mean: f64, phi: f64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let e = Normal::new(0.0, 1.0).unwrap();
    let mut x = mean + e.sample(&mut rng) / (1.0 - phi * phi).sqrt();
    (0..n)
        .map(|_| {
            let out = x;
            x = mean + phi * (x - mean) + e.sample(&mut rng);
            out
        })
        .collect()
}

/// Exact variance of the mean of n samples of that AR(1):
/// `(σ²/n) [1 + 2 Σ_{k=1}^{n−1} (1 − k/n) φ^k]`, `σ² = 1/(1 − φ²)`.
fn ar1_var_of_mean(n: usize, phi: f64) -> f64 {
    let s2 = 1.0 / (1.0 - phi * phi);
    let mut sum = 0.0;
    let mut pk = 1.0;
    for k in 1..n {
        pk *= phi;
        sum += (1.0 - k as f64 / n as f64) * pk;
    }
    s2 / n as f64 * (1.0 + 2.0 * sum)
}

#[test]
fn block_averaging_standard_error_on_ar1_series() {
    // 2^16 samples, correlation times up to ~50 samples: each estimate within a factor 1.3 of
    // the exact standard error (measured spread over 200 seeds: 0.80–1.25), and the mean
    // within 4 exact standard errors of μ
    let n = 1 << 16;
    let mut worst: f64 = 1.0;
    for (phi, seeds) in [(0.0, 0..4u64), (0.5, 4..8), (0.9, 8..12), (0.98, 12..16)] {
        let exact = ar1_var_of_mean(n, phi).sqrt();
        for seed in seeds {
            let x = ar1(seed, n, 3.5, phi);
            let avg = block_average(&x, MIN_BLOCKS).unwrap();
            let ratio = avg.std_error / exact;
            assert!(
                (1.0 / 1.3..1.3).contains(&ratio),
                "φ = {phi}, seed {seed}: SE {} vs exact {exact} (block {})",
                avg.std_error,
                avg.block_size
            );
            assert!(avg.converged, "φ = {phi}: no plateau");
            assert!((avg.mean - 3.5).abs() < 4.0 * exact);
            worst = worst.max(ratio.max(1.0 / ratio));
            // the naive (uncorrelated) error underestimates by √((1+φ)/(1−φ)) for φ > 0
            if phi >= 0.9 {
                assert!(avg.levels[0].std_error < 0.4 * exact);
            }
        }
    }
    assert!(worst < 1.3);
}

#[test]
fn block_averaging_rejects_bad_input() {
    assert!(block_average(&[1.0; 10], MIN_BLOCKS).is_err());
    let mut x = vec![0.0; 100];
    x[5] = f64::NAN;
    assert!(block_average(&x, MIN_BLOCKS).is_err());
    assert!(block_average(&[0.0; 100], 1).is_err());
    // a window skips missing values and keeps only the times inside
    let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.1).collect();
    let mut y: Vec<f64> = t
        .iter()
        .map(|&t| if t < 5.0 { 100.0 } else { 1.0 })
        .collect();
    y[150] = f64::NAN;
    let w = window_average(&t, &y, 5.0, 20.0, MIN_BLOCKS).unwrap();
    assert_eq!(w.samples, 149);
    assert!((w.mean - 1.0).abs() < 1e-15 && w.std_error == 0.0);
    assert!(window_average(&t, &y, 3.0, 1.0, MIN_BLOCKS).is_err());
}

#[test]
fn csv_tables_round_trip_with_units_and_are_written_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("history.csv");
    let mut t = Table::new(vec![
        Column::new("time", "s"),
        Column::new("pressure", "Pa"),
        Column::new("stress_ratio", "-"),
    ])
    .unwrap();
    t.push_row(&[0.0, 101.25, 0.3]).unwrap();
    t.push_row(&[1e-3, 1.0 / 3.0, f64::NAN]).unwrap();
    assert!(t.push_row(&[1.0]).is_err());
    assert!(t.push_row(&[1.0, f64::INFINITY, 0.0]).is_err());
    std::fs::write(&path, "old content\n").unwrap();
    t.write_csv(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("time [s],pressure [Pa],stress_ratio [-]\n"),
        "{text}"
    );
    assert!(text.contains("0.001,0.3333333333333333,\n"));
    // nothing left beside it
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1);
    let back = Table::read_csv(&path).unwrap();
    assert_eq!(back.columns(), t.columns());
    let (a, b) = (t.to_array(), back.to_array());
    assert_eq!(a.shape(), &[2, 3]);
    for (x, y) in a.iter().zip(b.iter()) {
        assert!(x == y || (x.is_nan() && y.is_nan()));
    }
    // a failed write leaves the old file as it was
    let missing_dir = dir.path().join("no/such/dir/h.csv");
    assert!(t.write_csv(&missing_dir).is_err());
    // errors name the line
    std::fs::write(&path, "time [s],p [Pa]\n0,1\n0.1,abc\n").unwrap();
    let e = Table::read_csv(&path).unwrap_err().to_string();
    assert!(e.contains("line 3"), "{e}");
    std::fs::write(&path, "time,p [Pa]\n0,1\n").unwrap();
    assert!(Table::read_csv(&path).is_err());
    assert!(Table::new(vec![Column::new("a", "s"), Column::new("a", "m")]).is_err());
    assert!(Table::new(vec![Column::new("a,b", "s")]).is_err());
}

#[test]
fn sampler_every_k_steps() {
    let config = SamplerConfig {
        every: 3,
        ..SamplerConfig::default()
    };
    let mut sampler = Sampler::new(config).unwrap();
    let mut sampled = 0;
    for step in 0..10u64 {
        let mut snap = support::random_dynamic(step, 5, 4, v(0.0, 0.0));
        snap.step = step;
        snap.time = step as f64 * snap.dt;
        if sampler.observe(&snap).unwrap() {
            sampled += 1;
        }
    }
    assert_eq!(sampled, 4); // steps 0, 3, 6, 9
    let table = sampler.table().unwrap();
    assert_eq!(table.rows(), 4);
    let steps = table.column("step").unwrap();
    assert_eq!(steps.to_vec(), vec![0.0, 3.0, 6.0, 9.0]);
    let skew = table.column("skew_ratio").unwrap();
    assert!(skew.iter().all(|s| *s <= 1e-8));
    let cols: Vec<String> = table.columns().iter().map(Column::header).collect();
    for h in [
        "time [s]",
        "sigma_xy [Pa]",
        "pressure [Pa]",
        "shear_rate [1/s]",
        "inertial_number [-]",
        "coordination_nonrattler [-]",
        "wall_left_fx [N]",
        "wall_bottom_fy [N]",
        "fluid_fraction [-]",
    ] {
        assert!(cols.iter().any(|c| c == h), "missing {h}");
    }
    // pressure column agrees with −tr Σ/2 of the same row
    let arr = table.to_array();
    let j = |n: &str| table.index_of(n).unwrap();
    for row in arr.rows() {
        let p = -(row[j("sigma_xx")] + row[j("sigma_yy")]) / 2.0;
        assert!((row[j("pressure")] - p).abs() <= 1e-12 * p.abs());
    }
    // the history goes to CSV and back
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("h.csv");
    table.write_csv(&path).unwrap();
    assert_eq!(Table::read_csv(&path).unwrap().rows(), 4);
    assert!(Sampler::new(SamplerConfig {
        every: 0,
        ..SamplerConfig::default()
    })
    .is_err());
}
