//! Standalone frictional-contact problems: every reference problem of `datasets/fc-problems/`
//! (Siconos' test suite and the pile generator) is solved to the error measure of
//! fc-problem-v1 ≤ 1e-6, and the error is recomputed here independently from `r` (own JSON
//! parse, `u = W r + q` from the COO triplets, own cone projection), plus reader errors, warm
//! start, non-convergence reporting and an analytic column of disks.

use std::io::Read;
use std::path::{Path, PathBuf};

use dem::fc::{
    read_problem, solve, Acceleration, BlockCsr2, ContactOrdering, FcError, FcOptions, FcProblem,
    FcSolution,
};
use serde_json::Value;

const TOL: f64 = 1e-6;

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../datasets/fc-problems")
}

/// The problem as read independently of `dem::fc`: μ, q and W as scalar COO triplets.
struct Raw {
    mu: Vec<f64>,
    q: Vec<f64>,
    row: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
}

fn read_raw(path: &Path) -> Raw {
    let mut bytes = Vec::new();
    let f = std::fs::File::open(path).unwrap();
    if path.to_string_lossy().ends_with(".gz") {
        flate2::read::GzDecoder::new(f)
            .read_to_end(&mut bytes)
            .unwrap();
    } else {
        std::io::BufReader::new(f).read_to_end(&mut bytes).unwrap();
    }
    let v: Value = serde_json::from_slice(&bytes).unwrap();
    let nums = |v: &Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let ints = |v: &Value| -> Vec<usize> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap() as usize)
            .collect()
    };
    let w = &v["W"];
    let (row, col, val) = if w["storage"] == "dense" {
        let (mut r, mut c, mut x) = (vec![], vec![], vec![]);
        for (i, line) in w["data"].as_array().unwrap().iter().enumerate() {
            for (j, a) in nums(line).into_iter().enumerate() {
                r.push(i);
                c.push(j);
                x.push(a);
            }
        }
        (r, c, x)
    } else {
        (ints(&w["row"]), ints(&w["col"]), nums(&w["val"]))
    };
    Raw {
        mu: nums(&v["mu"]),
        q: nums(&v["q"]),
        row,
        col,
        val,
    }
}

/// Projection on {(x_n, x_t): |x_t| ≤ μ x_n}, written from the formula.
fn project(xn: f64, xt: f64, mu: f64) -> (f64, f64) {
    if xn >= 0.0 && xt.abs() <= mu * xn {
        (xn, xt)
    } else if mu * xt.abs() <= -xn {
        (0.0, 0.0)
    } else {
        let a = (xn + mu * xt.abs()) / (1.0 + mu * mu);
        (a, mu * a * xt.signum())
    }
}

/// e = ‖r − proj_K(r − ū)‖ / max(‖q‖, ‖r‖, ‖u‖), u = W r + q, ū = u + μ|u_t| n.
fn independent_error(raw: &Raw, r: &[f64]) -> (f64, Vec<f64>) {
    let mut u = raw.q.clone();
    for k in 0..raw.val.len() {
        u[raw.row[k]] += raw.val[k] * r[raw.col[k]];
    }
    let mut res2 = 0.0;
    for (a, &mu) in raw.mu.iter().enumerate() {
        let (rn, rt, un, ut) = (r[2 * a], r[2 * a + 1], u[2 * a], u[2 * a + 1]);
        let (pn, pt) = project(rn - (un + mu * ut.abs()), rt - ut, mu);
        res2 += (rn - pn).powi(2) + (rt - pt).powi(2);
    }
    let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
    let scale = norm(&raw.q).max(norm(r)).max(norm(&u));
    let e = if scale > f64::EPSILON {
        res2.sqrt() / scale
    } else {
        res2.sqrt()
    };
    (e, u)
}

/// Checks a solution against the independent recomputation: reported error equal to the
/// recomputed one within 1e-9 relative (plus 1e-15 absolute: rounding of two summation orders),
/// reported u equal to W r + q (within 1e-12 of the size of its terms), and every r in its cone
/// (relative 1e-12).
fn check_solution(name: &str, raw: &Raw, s: &FcSolution) -> f64 {
    let (e, u) = independent_error(raw, &s.r);
    assert!(
        (e - s.error).abs() <= 1e-9 * e + 1e-15,
        "{name}: reported error {:e}, recomputed {e:e}",
        s.error
    );
    // u is a sum with cancellation (sticking contacts have u ≈ 0 from terms of size g h): compare
    // each component within 1e-12 of the magnitude of its terms, |q_i| + Σ_j |W_ij r_j|.
    let mut mag: Vec<f64> = raw.q.iter().map(|x| x.abs()).collect();
    for k in 0..raw.val.len() {
        mag[raw.row[k]] += (raw.val[k] * s.r[raw.col[k]]).abs();
    }
    for (i, (a, b)) in u.iter().zip(&s.u).enumerate() {
        assert!(
            (a - b).abs() <= 1e-12 * mag[i],
            "{name}: u[{i}] {b:e} vs W r + q = {a:e}"
        );
    }
    for (a, &mu) in raw.mu.iter().enumerate() {
        let (rn, rt) = (s.r[2 * a], s.r[2 * a + 1]);
        assert!(rn >= 0.0, "{name}: contact {a} r_n = {rn:e} < 0");
        assert!(
            rt.abs() <= mu * rn * (1.0 + 1e-12),
            "{name}: contact {a} |r_t| = {:e} > μ r_n = {:e}",
            rt.abs(),
            mu * rn
        );
    }
    e
}

fn solve_and_check(path: &Path, options: &FcOptions) -> FcSolution {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let p = read_problem(path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let raw = read_raw(path);
    assert_eq!(p.contacts(), raw.mu.len());
    let s = solve(&p, options).unwrap();
    let e = check_solution(&name, &raw, &s);
    assert!(
        s.converged && e <= options.tolerance,
        "{name}: not converged, error {e:e} after {} sweeps",
        s.iterations
    );
    s
}

fn files_in(sub: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(data_dir().join(sub))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".json.gz"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_pile_and_siconos_problem_converges_to_1e_6() {
    let piles = files_in("piles");
    let siconos = files_in("siconos-2d");
    assert_eq!(piles.len(), 2, "piles/: {piles:?}");
    assert_eq!(siconos.len(), 5, "siconos-2d/: {siconos:?}");
    for f in piles.iter().chain(&siconos) {
        solve_and_check(f, &FcOptions::default());
    }
}

#[test]
fn large_pile_converges_to_1e_6() {
    // 9891 contacts (the pile generator of `docs/formats.md` §1.3, 10000 contacts, seed 1): Siconos' NSGS needs
    // about 5900 sweeps here.
    let s = solve_and_check(
        &data_dir().join("large/pile_pert_10000.json.gz"),
        &FcOptions::default(),
    );
    assert!(s.iterations < 2000, "{} sweeps", s.iterations);
}

#[test]
fn plain_gauss_seidel_and_other_orderings_converge() {
    let pile = data_dir().join("piles/pile_pert_100.json.gz");
    let crank = data_dir().join("siconos-2d/FC2D_SliderCrankLagrangian00000.json.gz");
    for f in [&pile, &crank] {
        solve_and_check(
            f,
            &FcOptions {
                acceleration: Acceleration::None,
                ..FcOptions::default()
            },
        );
        solve_and_check(
            f,
            &FcOptions {
                acceleration: Acceleration::None,
                omega: 1.5,
                ..FcOptions::default()
            },
        );
    }
    let pile1000 = data_dir().join("piles/pile_pert_1000.json.gz");
    for ordering in [ContactOrdering::Natural, ContactOrdering::ReverseLoadFront] {
        solve_and_check(
            &pile1000,
            &FcOptions {
                ordering,
                ..FcOptions::default()
            },
        );
    }
    // A tighter tolerance is reached too.
    solve_and_check(
        &pile,
        &FcOptions {
            tolerance: 1e-10,
            ..FcOptions::default()
        },
    );
}

#[test]
fn warm_start_from_the_solution_needs_no_sweep() {
    let path = data_dir().join("siconos-2d/fc2d_granularflowonwall_02020_00213.json.gz");
    let cold = solve_and_check(&path, &FcOptions::default());
    assert!(cold.iterations > 10);
    let warm = solve_and_check(
        &path,
        &FcOptions {
            initial_guess: Some(cold.r.clone()),
            ..FcOptions::default()
        },
    );
    assert_eq!(warm.iterations, 0);
    assert_eq!(warm.r, cold.r);
}

#[test]
fn non_convergence_is_reported_with_the_true_error() {
    let path = data_dir().join("piles/pile_pert_1000.json.gz");
    let p = read_problem(&path).unwrap();
    let raw = read_raw(&path);
    for acceleration in [Acceleration::None, Acceleration::default()] {
        let s = solve(
            &p,
            &FcOptions {
                max_iterations: 3,
                acceleration,
                ..FcOptions::default()
            },
        )
        .unwrap();
        assert!(!s.converged);
        assert!(s.iterations <= 3);
        let e = check_solution("pile_pert_1000 (3 sweeps)", &raw, &s);
        assert!(e > TOL, "error {e:e} after 3 sweeps");
    }
}

/// A column of N disks (mass m) on a floor, one Moreau–Jean step from rest under gravity g with
/// step h, frictionless-like tangential decoupling: contact k (k = 0 floor–disk 0, k ≥ 1 disk
/// k−1 – disk k) has u_n = v_k − v_{k−1}, so W_nn = 1/m (floor) or 2/m, W_{k,k±1} = −1/m, and
/// q_n = −g h at the floor, 0 elsewhere. The exact impulses are r_n,k = (N − k) m g h, r_t = 0.
#[test]
fn column_of_disks_carries_the_weight_above() {
    let (n, m, g, h, mu) = (12usize, 0.7, 9.81, 1e-3, 0.4);
    let (mut row, mut col, mut val) = (vec![], vec![], vec![]);
    for k in 0..n {
        let (i, t) = (2 * k, 2 * k + 1);
        row.push(i);
        col.push(i);
        val.push(if k == 0 { 1.0 / m } else { 2.0 / m });
        row.push(t);
        col.push(t);
        val.push(if k == 0 { 3.0 / m } else { 6.0 / m });
        if k + 1 < n {
            for (a, b) in [(i, i + 2), (i + 2, i)] {
                row.push(a);
                col.push(b);
                val.push(-1.0 / m);
            }
        }
    }
    let mut q = vec![0.0; 2 * n];
    q[0] = -g * h;
    let w = BlockCsr2::from_triplets(n, &row, &col, &val).unwrap();
    let p = FcProblem::new(vec![mu; n], q, w).unwrap();
    for acceleration in [Acceleration::None, Acceleration::default()] {
        let s = solve(
            &p,
            &FcOptions {
                tolerance: 1e-12,
                acceleration,
                ..FcOptions::default()
            },
        )
        .unwrap();
        assert!(s.converged, "error {:e}", s.error);
        for k in 0..n {
            let exact = (n - k) as f64 * m * g * h;
            assert!(
                (s.r[2 * k] - exact).abs() <= 1e-9 * exact,
                "contact {k}: r_n = {:e}, exact {exact:e}",
                s.r[2 * k]
            );
            assert!(
                s.r[2 * k + 1].abs() <= 1e-12 * exact,
                "contact {k}: r_t = {:e}",
                s.r[2 * k + 1]
            );
        }
    }
}

// ----------------------------------------------------------------------------- reader errors

fn parse(s: &str) -> Result<FcProblem, FcError> {
    dem::fc::reader::parse_problem(s.as_bytes())
}

const GOOD: &str = r#"{"format": "fc-problem-v1", "dimension": 2, "nc": 2, "mu": [0.3, 0.5],
 "q": [-1.0, 0.1, 0.5, 0.0],
 "W": {"storage": "coo", "shape": [4, 4], "row": [0, 1, 2, 3, 0, 2], "col": [0, 1, 2, 3, 2, 0],
       "val": [2.0, 6.0, 2.0, 6.0, -1.0, -1.0]}}"#;

#[test]
fn a_valid_problem_reads_and_dense_storage_equals_coo() {
    let p = parse(GOOD).unwrap();
    assert_eq!(p.contacts(), 2);
    assert_eq!(p.w().diagonal(0), [2.0, 0.0, 0.0, 6.0]);
    let dense = r#"{"dimension": 2, "nc": 2, "mu": [0.3, 0.5], "q": [-1.0, 0.1, 0.5, 0.0],
      "W": {"storage": "dense", "data": [[2, 0, -1, 0], [0, 6, 0, 0], [-1, 0, 2, 0], [0, 0, 0, 6]]}}"#;
    let d = parse(dense).unwrap();
    assert_eq!(d.w(), p.w());
    let (a, b) = (
        solve(&p, &FcOptions::default()).unwrap(),
        solve(&d, &FcOptions::default()).unwrap(),
    );
    assert_eq!(a.r, b.r);
}

#[test]
fn reader_errors_name_the_key() {
    let cases: Vec<(String, &str)> = vec![
        (
            GOOD.replace(r#""q": [-1.0, 0.1, 0.5, 0.0]"#, r#""q": [-1.0, 0.1, 0.5]"#),
            "key `q`: length 3, expected 4",
        ),
        (
            GOOD.replace(r#""shape": [4, 4]"#, r#""shape": [4, 6]"#),
            "key `W.shape`: W is 4×6, not square",
        ),
        (
            GOOD.replace(r#""shape": [4, 4]"#, r#""shape": [6, 6]"#),
            "key `W.shape`: length 6, expected 4",
        ),
        (
            GOOD.replace(r#""mu": [0.3, 0.5]"#, r#""mu": [0.3, -0.5]"#),
            "key `mu[1]`: friction coefficient -0.5 < 0",
        ),
        (
            GOOD.replace(r#""mu": [0.3, 0.5]"#, r#""mu": [0.3]"#),
            "key `mu`: length 1, expected 2",
        ),
        (
            GOOD.replace(
                r#""row": [0, 1, 2, 3, 0, 2]"#,
                r#""row": [0, 1, 2, 3, 0, 4]"#,
            ),
            "key `W.row[5]`: index 4 out of range 0..4",
        ),
        (
            GOOD.replace(r#""col": [0, 1, 2, 3, 2, 0]"#, r#""col": [0, 1, 2, 3, 2]"#),
            "key `W.col`: length 5, expected 6",
        ),
        (GOOD.replace(r#""nc": 2, "#, ""), "missing key `nc`"),
        (
            GOOD.replace(r#""val": [2.0"#, r#""vals": [2.0"#),
            "missing key `W.val`",
        ),
        (
            GOOD.replace(r#""dimension": 2"#, r#""dimension": 3"#),
            "3D problems are not supported yet",
        ),
        (
            GOOD.replace(r#""dimension": 2"#, r#""dimension": 2.5"#),
            "key `dimension`",
        ),
        (GOOD.replace(r#""q": [-1.0"#, r#""q": ["x""#), "key `q[0]`"),
        (
            GOOD.replace(r#""q": [-1.0"#, r#""q": [NaN"#),
            "key `q`: non-finite value",
        ),
        (
            GOOD.replace(r#""val": [2.0"#, r#""val": [1e999"#),
            "key `val`: non-finite value",
        ),
        (
            GOOD.replace(r#""storage": "coo""#, r#""storage": "csr""#),
            "key `W.storage`",
        ),
        (
            GOOD.replace(r#""val": [2.0, 6.0"#, r#""val": [-2.0, 6.0"#),
            "not positive definite",
        ),
        (GOOD[..GOOD.len() / 2].to_string(), "invalid JSON"),
        ("[1, 2]".to_string(), "expected a JSON object"),
    ];
    for (text, expect) in cases {
        let e = parse(&text)
            .err()
            .unwrap_or_else(|| panic!("accepted: {text}"));
        let msg = e.to_string();
        assert!(
            msg.contains(expect),
            "message {msg:?} does not contain {expect:?}"
        );
    }
    // Truncation is a JSON error that says where and in which key it happened.
    let cut = &GOOD[..GOOD.find("\"val\"").unwrap() + 12];
    match parse(cut) {
        Err(FcError::Json { near, .. }) => assert!(near.contains("val"), "near = {near:?}"),
        other => panic!("expected a JSON error, got {other:?}"),
    }
    assert!(matches!(
        parse(&GOOD.replace(r#""dimension": 2"#, r#""dimension": 3"#)),
        Err(FcError::Unsupported3D { dimension: 3 })
    ));
}

/// A content error read from a file names the file first, then the key; the inner error is
/// still matched through `FcError::kind`. A valid file reads with no wrapping.
#[test]
fn file_errors_name_the_file_then_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad-mu.json");
    std::fs::write(&path, GOOD.replace("[0.3, 0.5]", "[0.3, -0.5]")).unwrap();
    let e = read_problem(&path).unwrap_err();
    let msg = e.to_string();
    let shown = path.display().to_string();
    assert!(
        msg.starts_with(&format!("{shown}: key `mu[1]`")),
        "message {msg:?} does not start with the file then the key"
    );
    assert!(matches!(
        e.kind(),
        FcError::NegativeFriction { contact: 1, value } if *value == -0.5
    ));
    let path3 = dir.path().join("three-d.json");
    std::fs::write(
        &path3,
        GOOD.replace(r#""dimension": 2"#, r#""dimension": 3"#),
    )
    .unwrap();
    let e = read_problem(&path3).unwrap_err();
    assert!(
        e.to_string().contains("three-d.json: key `dimension`"),
        "{e}"
    );
    assert!(matches!(e.kind(), FcError::Unsupported3D { dimension: 3 }));
    // Parsing text (no file) gives the bare error, not wrapped.
    let bare = parse(&GOOD.replace("[0.3, 0.5]", "[0.3, -0.5]")).unwrap_err();
    assert!(matches!(bare, FcError::NegativeFriction { .. }), "{bare:?}");
    let ok = dir.path().join("good.json");
    std::fs::write(&ok, GOOD).unwrap();
    assert_eq!(read_problem(&ok).unwrap().contacts(), 2);
}

#[test]
fn an_empty_problem_is_solved_by_r_empty() {
    let p = parse(r#"{"dimension": 2, "nc": 0, "mu": [], "q": [], "W": {"shape": [0, 0], "row": [], "col": [], "val": []}}"#)
        .unwrap();
    let s = solve(&p, &FcOptions::default()).unwrap();
    assert!(s.converged && s.r.is_empty() && s.u.is_empty() && s.iterations == 0 && s.error == 0.0);
    let e = parse(&GOOD.replace("fc-problem-v1", "fc-problem-v9")).unwrap_err();
    assert!(e.to_string().contains("key `format`"), "{e}");
}

#[test]
fn invalid_options_are_rejected() {
    let p = parse(GOOD).unwrap();
    for o in [
        FcOptions {
            initial_guess: Some(vec![0.0; 3]),
            ..FcOptions::default()
        },
        FcOptions {
            initial_guess: Some(vec![f64::NAN; 4]),
            ..FcOptions::default()
        },
        FcOptions {
            tolerance: 0.0,
            ..FcOptions::default()
        },
        FcOptions {
            omega: 2.0,
            ..FcOptions::default()
        },
        FcOptions {
            check_every: 0,
            ..FcOptions::default()
        },
        FcOptions {
            acceleration: Acceleration::Anderson { memory: 0 },
            ..FcOptions::default()
        },
    ] {
        assert!(
            matches!(solve(&p, &o), Err(FcError::Option { .. })),
            "{o:?}"
        );
    }
}

#[test]
fn gzip_and_plain_files_read_the_same_and_solutions_are_written_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let gz = data_dir().join("piles/pile_pert_100.json.gz");
    let mut text = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(&gz).unwrap())
        .read_to_end(&mut text)
        .unwrap();
    let plain = dir.path().join("pile.json");
    std::fs::write(&plain, &text).unwrap();
    let (a, b) = (read_problem(&gz).unwrap(), read_problem(&plain).unwrap());
    assert_eq!(a.q(), b.q());
    assert_eq!(a.w(), b.w());

    let out = dir.path().join("solution.json");
    let options = FcOptions {
        tolerance: 1e-8,
        ..FcOptions::default()
    };
    let (solution, _) = dem::fc::solve_by(
        &b,
        &options,
        dem::fc::SolverMethod::default(),
        &dem::fc::NewtonParams::default(),
    )
    .unwrap();
    assert!(solution.converged && solution.error <= 1e-8);
    dem::fc::write_solution(&out, &solution).unwrap();
    let v: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    let r: Vec<f64> = serde_json::from_value(v["r"].clone()).unwrap();
    // serde_json writes the shortest representation that round-trips; its default (fast) parser
    // may be one unit in the last place off.
    for (a, b) in r.iter().zip(&solution.r) {
        assert!(
            (a - b).abs() <= 2.3e-16 * b.abs(),
            "r round-trips to 1 ulp: {a:e} vs {b:e}"
        );
    }
    assert_eq!(
        v["iterations"].as_u64().unwrap() as usize,
        solution.iterations
    );
    assert_eq!(v["error"].as_f64().unwrap(), solution.error);
    assert_eq!(v["u"].as_array().unwrap().len(), r.len());
    assert!(v["seconds"].as_f64().unwrap() >= 0.0);
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "no temporary file left behind: {names:?}");
    // An unreadable problem is an I/O error naming the path (that nothing is written then is
    // checked on `grainlaw::fc_cmd::solve_file`).
    let missing = dir.path().join("missing.json");
    let e = read_problem(&missing).unwrap_err();
    assert!(e.to_string().contains("missing.json"));
}

/// Random rigid-body problems: disks (3 degrees of freedom each, random mass and radius) touching
/// each other or a fixed ground at random points with random normals, `W = H M⁻¹ Hᵀ`,
/// `q = H v_free` with random free velocities, μ random in [0, 0.8] (some contacts frictionless).
/// At most 1.5 contacts per disk, but drawn at random, so W can be singular where contacts crowd
/// one disk. Every seeded problem is solved to 1e-10 with and without acceleration and checked
/// independently.
#[test]
fn random_rigid_body_problems_converge() {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    let mut solved = 0;
    for seed in 0..20u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let bodies = rng.random_range(3..12usize);
        let mass: Vec<f64> = (0..bodies).map(|_| rng.random_range(0.1..2.0)).collect();
        let radius: Vec<f64> = (0..bodies).map(|_| rng.random_range(0.01..0.1)).collect();
        let nc = rng.random_range(1..(3 * bodies) / 2);
        // H (2 nc × 3 bodies), dense; body `bodies` is the fixed ground.
        let mut h = vec![vec![0.0f64; 3 * bodies]; 2 * nc];
        let mut mu = Vec::new();
        for c in 0..nc {
            let j = rng.random_range(0..bodies);
            let i = rng.random_range(0..=bodies);
            let i = if i == j { bodies } else { i };
            let a: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let (n, t) = ([a.cos(), a.sin()], [-a.sin(), a.cos()]);
            h[2 * c][3 * j] = n[0];
            h[2 * c][3 * j + 1] = n[1];
            h[2 * c + 1][3 * j] = t[0];
            h[2 * c + 1][3 * j + 1] = t[1];
            h[2 * c + 1][3 * j + 2] = -radius[j];
            if i < bodies {
                h[2 * c][3 * i] = -n[0];
                h[2 * c][3 * i + 1] = -n[1];
                h[2 * c + 1][3 * i] = -t[0];
                h[2 * c + 1][3 * i + 1] = -t[1];
                h[2 * c + 1][3 * i + 2] = -radius[i];
            }
            mu.push(if rng.random_bool(0.2) {
                0.0
            } else {
                rng.random_range(0.0..0.8)
            });
        }
        let minv: Vec<f64> = (0..3 * bodies)
            .map(|k| {
                let b = k / 3;
                if k % 3 == 2 {
                    2.0 / (mass[b] * radius[b] * radius[b])
                } else {
                    1.0 / mass[b]
                }
            })
            .collect();
        let v_free: Vec<f64> = (0..3 * bodies)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let (mut row, mut col, mut val) = (vec![], vec![], vec![]);
        for a in 0..2 * nc {
            for b in 0..2 * nc {
                let w: f64 = (0..3 * bodies).map(|k| h[a][k] * minv[k] * h[b][k]).sum();
                if w != 0.0 {
                    row.push(a);
                    col.push(b);
                    val.push(w);
                }
            }
        }
        let q: Vec<f64> = (0..2 * nc)
            .map(|a| (0..3 * bodies).map(|k| h[a][k] * v_free[k]).sum())
            .collect();
        let raw = Raw {
            mu: mu.clone(),
            q: q.clone(),
            row: row.clone(),
            col: col.clone(),
            val: val.clone(),
        };
        let w = BlockCsr2::from_triplets(nc, &row, &col, &val).unwrap();
        let p = match FcProblem::new(mu, q, w) {
            Ok(p) => p,
            // Two contacts on the same body pair and direction can make a block singular.
            Err(FcError::NotPositiveDefinite { .. }) => continue,
            Err(e) => panic!("seed {seed}: {e}"),
        };
        for acceleration in [Acceleration::None, Acceleration::default()] {
            let s = solve(
                &p,
                &FcOptions {
                    tolerance: 1e-10,
                    acceleration,
                    ..FcOptions::default()
                },
            )
            .unwrap();
            let e = check_solution(&format!("random seed {seed}"), &raw, &s);
            assert!(
                s.converged && e <= 1e-10,
                "seed {seed} ({acceleration:?}): error {e:e} after {} sweeps",
                s.iterations
            );
        }
        solved += 1;
    }
    assert!(
        solved >= 15,
        "only {solved} of 20 random problems were well posed"
    );
}
