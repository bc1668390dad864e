//! Other codes' representative volumes: a real LAMMPS simple shear of 300 disks in a
//! biperiodic, tilting cell (`datasets/external/lammps-rve`, made with the LAMMPS of Debian 12,
//! its README), read by `grainlaw homogenise --from lammps` and checked against LAMMPS' own
//! numbers; LAMMPS boxes of every kind (orthogonal, triclinic, periodic per axis) and the
//! dumps the reader refuses.

mod common;

use common::grainlaw_here as grainlaw;

use std::path::{Path, PathBuf};
use std::process::Command;

use dem::snapshot::BodyKind;
use grainlaw::readers::{self, GradientSource, ReadOptions};
use homogenise::tensor::Tensor2;
use homogenise::{grain_stresses, Region};

fn rve(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("datasets/external/lammps-rve")
        .join(rel)
}

/// The inertial numbers of the committed run (one directory each).
const TARGETS: [&str; 10] = [
    "0.003", "0.006", "0.01", "0.02", "0.03", "0.06", "0.1", "0.2", "0.3", "0.5",
];

/// Rows of a LAMMPS thermo file (the lines after its `Step` header).
fn thermo(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("Step"))
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// The exact snapshot (a `run 0` setup, full precision) after the window of I = `i`.
fn exact_files(i: &str) -> Vec<PathBuf> {
    let dir = rve("exact");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().to_string();
            n.ends_with(".dump.gz") && n.contains(&format!(".I{i}."))
        })
        .collect();
    files.sort();
    assert_eq!(files.len(), 2, "{files:?}");
    files
}

fn series_files(i: &str) -> Vec<PathBuf> {
    let d = rve(&format!("I{i}"));
    vec![d.join("atoms.dump.gz"), d.join("pairs.dump.gz")]
}

/// `Σ_p V_p Σ_c,p` over the grains (N·m per metre): the pair moment.
fn pair_moment(s: &dem::Snapshot) -> Tensor2 {
    grain_stresses(s)
        .unwrap()
        .iter()
        .fold(Tensor2::zeros(), |m, g| m + g.contact * g.volume)
}

#[test]
fn tilted_biperiodic_contact_stress_equals_lammps_stress_atom() {
    // Two snapshots written at the setup of a `run 0` (forces, positions and cell of one
    // state): Σ_p V_p Σ_c,p from the pair forces with the minimum image of the tilted cell
    // against the sum of LAMMPS' per-atom pair stress (and its thermo `reduce sum`), to 1e-6
    // relative (measured 2e-13: the rounding of the sums). LAMMPS' xy (branch x, force y) is
    // grainlaw's yx (docs/formats.md §7.1).
    for i in ["0.003", "0.03"] {
        let files = exact_files(i);
        let snaps = readers::read_lammps(&files, &ReadOptions::default()).unwrap();
        assert_eq!(snaps.len(), 1);
        let s = &snaps[0].snapshot;
        let cell = s.cell.expect("a biperiodic cell");
        let th = &thermo(&rve(&format!("exact/thermo_I{i}.txt")))[0];
        // Step Time c_spair[1..3] Lx Ly Xy Volume
        let (lx, ly, xy, area) = (th[5], th[6], th[7], th[8]);
        assert!((cell.h[(0, 0)] - lx).abs() <= 1e-15 * lx);
        assert!((cell.h[(1, 1)] - ly).abs() <= 1e-15 * ly);
        assert!((cell.h[(0, 1)] - xy).abs() <= 1e-15 * lx);
        assert!((cell.volume() - area).abs() <= 1e-12 * area);
        // the cell is tilted, and contacts cross its y boundary: the contact point seen from
        // the two grains differs by a lattice shift with a y part (a₂ = (xy, l_y))
        assert!(xy.abs() > 0.1 * lx, "tilt {xy} of {lx}");
        let crossing = s
            .contacts
            .iter()
            .filter(|c| {
                let (a, b) = (&s.bodies[c.body_a as usize], &s.bodies[c.body_b as usize]);
                let shift = (b.position + c.lever_b) - (a.position + c.lever_a);
                shift.y.abs() > 0.5 * ly
            })
            .count();
        assert!(crossing >= 5, "{crossing} contacts across the y boundary");
        let m = pair_moment(s);
        let ours = [m[(0, 0)], m[(1, 1)], m[(1, 0)]];
        let atoms = files
            .iter()
            .find(|p| p.to_string_lossy().contains("atoms."))
            .unwrap();
        let lammps = common::lammps_stress_sum(atoms);
        let scale = lammps.iter().map(|v| v * v).sum::<f64>().sqrt();
        for k in 0..3 {
            assert!(
                (ours[k] - lammps[k]).abs() <= 1e-6 * scale,
                "I = {i}, component {k}: grainlaw {} LAMMPS {}",
                ours[k],
                lammps[k]
            );
            assert!((ours[k] - th[2 + k]).abs() <= 1e-6 * scale, "thermo {k}");
        }
        // compression: σ_yy of the contacts is negative (the x-only images of the former
        // reader made it tensile on such cells)
        assert!(m[(0, 0)] < 0.0 && m[(1, 1)] < 0.0);
        // the whole-sample solid fraction and stress are over the cell's area
        let disks: f64 = s
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .map(|b| std::f64::consts::PI * b.radius * b.radius)
            .sum();
        let phi = homogenise::state::solid_fraction(s, &Region::Whole).unwrap();
        assert!(
            (phi - disks / area).abs() <= 1e-12,
            "{phi} vs {}",
            disks / area
        );
        let g = grain_stresses(s).unwrap();
        let whole = homogenise::mean_stress(s, &g, &Region::Whole).unwrap();
        assert!((whole.contact[(1, 1)] - m[(1, 1)] / area).abs() <= 1e-9 * scale / area);
    }
}

/// The reference of a series from LAMMPS' thermo lines at the dump steps (`Step Time c_pr[1]
/// c_pr[2] c_pr[4] Lx Ly Xy Volume ...`, `c_pr` the pressure with the kinetic part about the
/// streaming profile): means of μ = |p_xy|/p_yy and φ = Σ π R² / area, and the cell's shear
/// rate (the tilt unwrapped by whole periods over the time).
fn lammps_reference(i: &str, disks: f64) -> (f64, f64, f64) {
    let th = thermo(&rve(&format!("I{i}/thermo.txt")));
    let n = th.len() as f64;
    let mu = th.iter().map(|t| t[4].abs() / t[3]).sum::<f64>() / n;
    let phi = th.iter().map(|t| disks / t[8]).sum::<f64>() / n;
    let mut strain = 0.0;
    for w in th.windows(2) {
        let mut dxy = w[1][7] - w[0][7];
        dxy -= w[0][5] * (dxy / w[0][5]).round();
        strain += dxy / (0.5 * (w[0][6] + w[1][6]));
    }
    let gamma = strain / (th[th.len() - 1][1] - th[0][1]);
    (mu, phi, gamma)
}

#[test]
fn rve_series_give_the_simple_shear_points_of_lammps_thermo() {
    // Each series: 16 snapshots 0.2 of strain apart in steady shear at one I. grainlaw's point
    // (cell_state per snapshot, block-averaged means) against LAMMPS' thermo at the same steps:
    // μ within its standard error (measured: at most 0.71 of it, at I = 0.3; the two differ by
    // the symmetrisation of the stress and the kinetic part's reference field), φ to 1e-6
    // (the same disks over the same area), the shear rate to 1e-9 (the same tilts), and the
    // rate of the grain velocities within 20 % of the cell's (the flow follows the cell).
    for i in TARGETS {
        let snaps = readers::read_lammps(&series_files(i), &ReadOptions::default()).unwrap();
        assert_eq!(snaps.len(), 16, "I = {i}");
        assert!(snaps
            .iter()
            .all(|e| e.velocity_gradient == Some(GradientSource::CellDeformation)));
        let p = grainlaw::rve::rve_point(&snaps).unwrap().expect("a point");
        let disks: f64 = snaps[0]
            .snapshot
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .map(|b| std::f64::consts::PI * b.radius * b.radius)
            .sum();
        let (mu, phi, gamma) = lammps_reference(i, disks);
        let (gmu, se) = (p.value("mu"), p.value("mu_std_error"));
        eprintln!(
            "I = {i}: grainlaw I = {:.4e}, μ = {gmu:.4} ± {se:.4}, φ = {:.5}; LAMMPS μ = {mu:.4}, φ = {phi:.5}",
            p.value("I"),
            p.value("phi")
        );
        assert!(
            se > 0.0 && (gmu - mu).abs() <= se,
            "I = {i}: μ {gmu} vs {mu} ± {se}"
        );
        assert!((p.value("phi") - phi).abs() <= 1e-6, "I = {i}: φ");
        assert!(p.value("phi_std_error") > 0.0);
        assert_eq!(p.source, GradientSource::CellDeformation);
        assert!(
            (p.shear_rate - gamma).abs() <= 1e-9 * gamma.abs(),
            "I = {i}: γ̇"
        );
        assert!(
            (p.shear_rate_velocity_profile / p.shear_rate - 1.0).abs() < 0.2,
            "I = {i}: {} vs {}",
            p.shear_rate_velocity_profile,
            p.shear_rate
        );
        // I = γ̇ d / √(P/ρ) with the grains' d and ρ (2500 kg/m², `density/disc`), near its
        // target (the servo holds P = 1 kPa on average)
        assert!((p.grain.density_kg_m3 - 2500.0).abs() < 1e-3);
        let target: f64 = i.parse().unwrap();
        assert!((p.value("I") / target - 1.0).abs() < 0.2, "I = {i}");
        assert_eq!(p.verdict, grainlaw::verdict::Verdict::Ok, "I = {i}");
        assert_eq!(
            grainlaw::scenarios::rows::TableRow::to_values(&p.row).len(),
            15
        );
    }
}

#[test]
fn a_single_snapshot_takes_its_shear_rate_from_the_grain_velocities() {
    // one snapshot of the I = 0.1 series: no interval to take the cell's rate over, the
    // velocity gradient of the cell is the affine fit of the grain velocities
    let files = series_files("0.1");
    let all = readers::read_lammps(&files, &ReadOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let text = readers::read_text(&files[0]).unwrap();
    let second = text.match_indices("ITEM: TIME\n").nth(1).unwrap().0;
    let one = dir.path().join("one_atoms.dump");
    std::fs::write(&one, &text[..second]).unwrap();
    let ptext = readers::read_text(&files[1]).unwrap();
    let psecond = ptext.match_indices("ITEM: TIMESTEP").nth(1).unwrap().0;
    let onep = dir.path().join("one_pairs.dump");
    std::fs::write(&onep, &ptext[..psecond]).unwrap();
    let s = readers::read_lammps(&[one, onep], &ReadOptions::default()).unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!(
        s[0].velocity_gradient,
        Some(GradientSource::VelocityProfile)
    );
    let fitted = s[0].snapshot.cell.unwrap().l[(0, 1)];
    let cell = all[1].snapshot.cell.unwrap().l[(0, 1)];
    assert!((fitted / cell - 1.0).abs() < 0.3, "{fitted} vs {cell}");
    // the same snapshot in the series has the cell's rate, L_xy = Δxy/(l_y Δt)
    assert_eq!(
        all[0].velocity_gradient,
        Some(GradientSource::CellDeformation)
    );
}

#[test]
fn rve_points_of_every_i_merge_into_the_laws() {
    // The documented commands: one `homogenise` per series, then `fit` on all their
    // rheology.csv at once (merged as campaign --collect merges).
    let dir = tempfile::tempdir().unwrap();
    let mut tables = Vec::new();
    for i in TARGETS {
        let out = dir.path().join(format!("I{i}"));
        let files = series_files(i);
        let paths = [&out, &files[0], &files[1]].map(|p| p.to_str().unwrap());
        let o = grainlaw(&[common::HOMOGENISE_LAMMPS, &paths].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let table = out.join("rheology.csv");
        let text = std::fs::read_to_string(&table).unwrap();
        assert!(text.contains("# grain_diameter_m = "), "{text}");
        assert!(text.contains("point_verdict"));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["rve_shear_rate_source"], "cell_deformation");
        assert_eq!(summary["rve_point_verdict"], "ok");
        assert!(summary["cell_area_m2"].as_f64().unwrap() > 0.0);
        tables.push(table.to_str().unwrap().to_string());
    }
    let fit = |law: &str| {
        let out = dir.path().join(format!("{law}.json"));
        let mut args = vec!["fit", law];
        args.extend(tables.iter().map(String::as_str));
        args.extend(["--out", out.to_str().unwrap()]);
        (grainlaw(&args), out)
    };
    for law in ["phi-i", "mu-i-linear"] {
        let (o, out) = fit(law);
        assert!(
            o.status.success(),
            "{law}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(json["fit"]["n"], 10);
        // every parameter with its interval, every table in the provenance
        for p in json["parameters"].as_array().unwrap() {
            assert!(p["ci_low"].as_f64().unwrap() < p["ci_high"].as_f64().unwrap());
        }
        assert_eq!(json["provenance"]["inputs"].as_array().unwrap().len(), 10);
    }
    // φ(I) of the run: φ_max near the I = 0.003 point (0.807), decreasing
    let (_, out) = fit("phi-i");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
    let phi_max = json["parameters"][0]["value"].as_f64().unwrap();
    assert!((phi_max - 0.808).abs() < 0.005, "{phi_max}");
    // the three-parameter μ(I) is refused on these ten points (I_0 not determined by a
    // 300-disk cell's scatter), naming the simpler form: exit 3, not bad input
    let (o, _) = fit("mu-i");
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("mu-i-linear"));
}

/// A per-atom dump of two disks of radius `r` (ids 1 and 2) at `a` and `b`, with the box
/// header `bounds` (the `ITEM: BOX BOUNDS` line and its three lines), and the local dump of
/// their contact: force `f` on atom 1 from atom 2.
fn two_disks(
    dir: &Path,
    step: u64,
    bounds: &str,
    a: [f64; 2],
    b: [f64; 2],
    r: f64,
    f: [f64; 2],
) -> Vec<PathBuf> {
    let m = 2500.0 * std::f64::consts::PI * r * r;
    let atoms = format!(
        "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\n{bounds}\nITEM: ATOMS id x y vx vy omegaz radius mass\n1 {} {} 0 0 0 {r} {m}\n2 {} {} 0 0 0 {r} {m}\n",
        a[0], a[1], b[0], b[1]
    );
    let pairs = format!(
        "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ENTRIES\n1\n{bounds}\nITEM: ENTRIES c_ids[1] c_ids[2] c_pf[1] c_pf[2] c_pf[3] c_pf[4] c_pf[5] c_pf[6]\n1 2 0 {} {} 0 0 0\n",
        f[0], f[1]
    );
    let pa = dir.join(format!("atoms.{step}.dump"));
    let pp = dir.join(format!("pairs.{step}.dump"));
    std::fs::write(&pa, atoms).unwrap();
    std::fs::write(&pp, pairs).unwrap();
    vec![pa, pp]
}

/// The branch vector `c_b − c_a` of the one contact of a snapshot (a = atom 2, b = atom 1).
fn branch(s: &dem::Snapshot) -> nalgebra::Vector2<f64> {
    let c = &s.contacts[0];
    // Love–Weber pair sum −F ⊗ (c_b − c_a) = Σ levers ⊗ ...: the branch from the levers
    c.lever_a - c.lever_b
}

#[test]
fn every_kind_of_lammps_box_gives_the_minimum_image() {
    // Two disks of radius 1 mm touching across a boundary, in boxes written as LAMMPS writes
    // them; the branch vector must be the 2 mm between the touching images, whatever the box.
    let dir = tempfile::tempdir().unwrap();
    let r = 1e-3;
    let read = |files: Vec<PathBuf>| {
        readers::read_lammps(&files, &ReadOptions::default())
            .unwrap()
            .remove(0)
    };
    // Triclinic, periodic in x only (`pp ff`): edges x ∈ [0, 10 mm] from the bounds
    // x_lo,bound = 0 + min(0, xy) = 0, x_hi,bound = 10 + max(0, xy) = 13 mm; disks at
    // x = 0.5 and 8.5 mm touch across x. The bounds' width (13 mm) would miss them.
    let e = read(two_disks(
        dir.path(),
        1,
        "ITEM: BOX BOUNDS xy xz yz pp ff pp\n0 0.013 0.003\n0 0.01 0\n-0.0005 0.0005 0",
        [0.0005, 0.005],
        [0.0085, 0.005],
        r,
        [1.0, 0.0],
    ));
    let [x0, x1] = e.snapshot.periodic_x.expect("periodic in x");
    assert!(
        x0.abs() < 1e-15 && (x1 - 0.01).abs() < 1e-15,
        "[{x0}, {x1}]"
    );
    assert!(e.snapshot.cell.is_none());
    let d = branch(&e.snapshot);
    assert!((d.norm() - 2e-3).abs() < 1e-12, "{d}");
    // Triclinic, biperiodic, tilt xy = 4 mm on a 10 × 10 mm cell: disk 1 at (1, 0.5) mm,
    // disk 2 at (5, 8.5) mm, whose image across y by −a₂ = (−4, −10) mm is at (1, −1.5) mm,
    // 2 mm below disk 1 (straight across y, without the tilt, they are 9 mm apart)
    let bounds = "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 0.014 0.004\n0 0.01 0\n-0.0005 0.0005 0";
    let (a, b) = ([0.001, 0.0005], [0.001 + 0.004, 0.0005 + 0.01 - 0.002]);
    let e = read(two_disks(dir.path(), 2, bounds, a, b, r, [0.0, 1.0]));
    let cell = e.snapshot.cell.expect("biperiodic");
    assert_eq!(cell.h, dem::math::Tensor::new(0.01, 0.004, 0.0, 0.01));
    // one snapshot of two disks: neither an interval nor enough grains for a velocity fit
    assert_eq!(e.velocity_gradient, Some(GradientSource::Zero));
    let d = branch(&e.snapshot);
    assert!(
        (d - nalgebra::Vector2::new(0.0, 0.002)).norm() < 1e-12
            || (d + nalgebra::Vector2::new(0.0, 0.002)).norm() < 1e-12,
        "{d}"
    );
    // the whole sample is the cell: φ = 2 π R² / (10 mm)²
    let phi = homogenise::state::solid_fraction(&e.snapshot, &Region::Whole).unwrap();
    assert!((phi - 2.0 * std::f64::consts::PI * r * r / 1e-4).abs() < 1e-12);
    // Orthogonal, periodic in y only (`ff pp`): disks at y = 0.5 and 8.5 mm touch across y
    let e = read(two_disks(
        dir.path(),
        3,
        "ITEM: BOX BOUNDS ff pp pp\n0 0.01\n0 0.01\n-0.0005 0.0005",
        [0.005, 0.0005],
        [0.005, 0.0085],
        r,
        [0.0, 1.0],
    ));
    assert!(e.snapshot.periodic_x.is_none() && e.snapshot.cell.is_none());
    assert!((branch(&e.snapshot).norm() - 2e-3).abs() < 1e-12);
    // Orthogonal, not periodic: no image, the centres are 8 mm apart
    let e = read(two_disks(
        dir.path(),
        4,
        "ITEM: BOX BOUNDS ff ff pp\n0 0.01\n0 0.01\n-0.0005 0.0005",
        [0.005, 0.0005],
        [0.005, 0.0085],
        r,
        [0.0, 1.0],
    ));
    assert!((branch(&e.snapshot).norm() - 8e-3).abs() < 1e-12);
}

/// Runs `grainlaw homogenise --from lammps` on `files`: (exit code, stderr).
fn homogenise_files(files: &[PathBuf], out: &Path) -> (Option<i32>, String) {
    let mut args = vec![
        "homogenise".to_string(),
        "--from".into(),
        "lammps".into(),
        "-q".into(),
        "--out".into(),
        out.display().to_string(),
    ];
    args.extend(files.iter().map(|p| p.display().to_string()));
    let o = Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(&args)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

#[test]
fn dumps_grainlaw_cannot_read_are_refused_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let one_line = |e: &str| e.trim_end().lines().count() == 1;
    // two disks 2 mm apart at rest in the box `bounds`, pushed apart, dumped at `step`
    let still = |step: u64, bounds: &str| {
        two_disks(
            dir.path(),
            step,
            bounds,
            [0.001, 0.001],
            [0.003, 0.001],
            1e-3,
            [1.0, 0.0],
        )
    };
    // a dump written as `text`
    let dump = |name: &str, text: &str| {
        let f = dir.path().join(name);
        std::fs::write(&f, text).unwrap();
        f
    };
    // the files refused with exit 2, the error naming the place `at` and saying `what`
    let refused = |files: &[PathBuf], at: &str, what: &str| {
        let (code, err) = homogenise_files(files, &out);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(at) && err.contains(what), "{err}");
        err
    };
    // a cell tilted beyond LAMMPS' limit (|xy| ≤ l_x / 2): 6 mm on 10 mm
    let files = still(
        1,
        "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 0.016 0.006\n0 0.01 0\n-0.0005 0.0005 0",
    );
    let err = refused(&files, "atoms.1.dump:5:", "0.600 of its x length");
    assert!(one_line(&err), "{err}");
    // 3D dumps: a non-periodic z, a z tilt, atoms off the plane
    let three_d = "3D is not supported yet";
    let files = still(2, "ITEM: BOX BOUNDS pp pp ff\n0 0.01\n0 0.01\n0 0.01");
    refused(&files, "atoms.2.dump:5:", three_d);
    let files = still(
        3,
        "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 0.01 0\n0 0.01 0.001\n0 0.01 0",
    );
    refused(&files, "atoms.3.dump:5:", three_d);
    let z = dump("atoms.4.dump", "ITEM: TIMESTEP\n4\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 0.01\n0 0.01\n0 0.01\nITEM: ATOMS id x y z vx vy omegaz radius mass\n1 0.001 0.001 0.005 0 0 0 0.001 0.008\n2 0.003 0.001 0.006 0 0 0 0.001 0.008\n");
    refused(&[z], "atoms.4.dump:11:", three_d);
    // a dump without a column the reader needs
    let nm = dump("atoms.5.dump", "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS xy xz yz pp pp pp\n0 0.01 0\n0 0.01 0\n0 0.01 0\nITEM: ATOMS id x y vx vy omegaz radius\n1 0.001 0.001 0 0 0 0.001\n");
    refused(&[nm], "atoms.5.dump:9:", "no column `mass`");
    // a series whose grain count changes, and one whose cell changes kind
    let flat = "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 0.01 0\n0 0.01 0\n0 0.01 0";
    let mut files = still(10, flat);
    files.push(dump("atoms.20.dump", "ITEM: TIMESTEP\n20\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS xy xz yz pp pp pp\n0 0.01 0\n0 0.01 0\n0 0.01 0\nITEM: ATOMS id x y vx vy omegaz radius mass\n1 0.001 0.001 0 0 0 0.001 0.008\n2 0.003 0.001 0 0 0 0.001 0.008\n3 0.005 0.005 0 0 0 0.001 0.008\n"));
    refused(&files, "atoms.20.dump:4:", "has 3 atoms where step 10");
    let mut files = still(30, flat);
    files.extend(still(
        40,
        "ITEM: BOX BOUNDS pp ff pp\n0 0.01\n0 0.01\n0 0.01",
    ));
    let err = refused(
        &files,
        "atoms.40.dump:5:",
        "the cell changes within the series",
    );
    assert!(one_line(&err), "{err}");
}

#[test]
fn a_refused_point_exits_with_code_3_after_writing_everything() {
    // 16 snapshots of a 2 × 2 mm cell sheared at 5 1/s holding two overlapping disks of
    // radius 0.8 mm: φ = 2π 0.64/4 = 1.005, above the densest packing of equal disks
    let dir = tempfile::tempdir().unwrap();
    let (r, m) = (8e-4, 2500.0 * std::f64::consts::PI * 8e-4 * 8e-4);
    let (mut atoms, mut pairs) = (String::new(), String::new());
    for k in 0..16u64 {
        let xy = 1e-5 * k as f64;
        let bounds = format!(
            "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 {} {xy}\n0 0.002 0\n-0.0005 0.0005 0",
            0.002 + xy
        );
        atoms += &format!(
            "ITEM: TIME\n{}\nITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n2\n{bounds}\nITEM: ATOMS id x y vx vy omegaz radius mass fx fy tqz\n1 0.0005 0.0005 0 0 0 {r} {m} 0 0 0\n2 0.0012 0.0013 0 0 0 {r} {m} 0 0 0\n",
            1e-3 * k as f64,
            1000 * k
        );
        pairs += &format!(
            "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ENTRIES\n1\n{bounds}\nITEM: ENTRIES c_ids[1] c_ids[2] c_pf[1] c_pf[2] c_pf[3] c_pf[4] c_pf[5] c_pf[6]\n1 2 0 -0.7 -0.8 0 0 0\n",
            1000 * k
        );
    }
    let (a, p) = (dir.path().join("atoms.dump"), dir.path().join("pairs.dump"));
    std::fs::write(&a, atoms).unwrap();
    std::fs::write(&p, pairs).unwrap();
    let out = dir.path().join("out");
    let (code, err) = homogenise_files(&[a, p], &out);
    assert_eq!(code, Some(3), "{err}");
    assert!(
        err.contains("the simple-shear point is refused") && err.contains("densest packing"),
        "{err}"
    );
    let table = std::fs::read_to_string(out.join("rheology.csv")).unwrap();
    assert!(table.trim_end().ends_with(",2e0"), "{table}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["rve_point_verdict"], "refused");
    // the cell's rate: Δxy / (l_y Δt) = 1e-5 / (2e-3 · 1e-3) = 5 1/s
    assert!((s["rve_shear_rate_1_s"].as_f64().unwrap() - 5.0).abs() < 1e-9);
}
