//! `grainlaw campaign`: the runs of a plan (Cartesian product), shares that partition them,
//! resumability (finished runs are not redone), collection and merged fits, bad plans.

mod common;

use std::path::Path;

use common::{campaign, plan_dir, text, Table};

/// A rolling disk sweep (2 frictions × 2 seeds): four runs in the product's order, each an
/// ordinary run whose summary matches the analytic acceleration (rolling: (2/3) g sin θ;
/// sliding: g (sin θ − μ cos θ)) to 1e-9 relative; a second call redoes nothing.
#[test]
fn sweep_runs_the_product_and_is_resumable() {
    let dir = plan_dir(
        "scenario = \"rolling\"\n[set]\nduration = 0.1\n[sweep]\nseed = [1, 2]\nfriction = [0.05, 0.5]\n",
    );
    let o = campaign(dir.path(), &["plan.toml", "--out", "c"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let c = dir.path().join("c");
    let table = std::fs::read_to_string(c.join("campaign.csv")).unwrap();
    let table = Table::parse(&table);
    let (col, rows) = (|n: &str| table.col(n), &table.rows);
    assert_eq!(rows.len(), 4);
    let g = 9.81f64;
    let th = 20f64.to_radians();
    for (k, r) in rows.iter().enumerate() {
        // keys sorted (friction, seed), seed fastest
        let mu: f64 = r[col("friction")].parse().unwrap();
        assert_eq!(mu, [0.05, 0.05, 0.5, 0.5][k]);
        assert_eq!(&r[col("seed")], ["1", "2", "1", "2"][k]);
        assert_eq!(&r[col("exit_status")], "0");
        let a: f64 = r[col("acceleration")].parse().unwrap();
        let expect = if mu >= th.tan() / 3.0 {
            2.0 / 3.0 * g * th.sin()
        } else {
            g * (th.sin() - mu * th.cos())
        };
        assert!(
            (a - expect).abs() <= 1e-9 * expect,
            "run {k}: a = {a}, expected {expect}"
        );
    }
    let log = c.join("runs/0000/summary.json");
    let before = std::fs::metadata(&log).unwrap().modified().unwrap();
    let o = campaign(dir.path(), &["plan.toml", "--out", "c"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("4 run(s) already finished"),
        "{}",
        text(&o)
    );
    assert_eq!(std::fs::metadata(&log).unwrap().modified().unwrap(), before);
    // Standard error over the two seeds: the rolling disk does not depend on the seed, so the
    // mean is the single value and the standard error 0.
    let stats = std::fs::read_to_string(c.join("campaign_stats.csv")).unwrap();
    assert!(
        stats
            .lines()
            .any(|l| l.starts_with("0.5,acceleration,2,") && l.ends_with(",0e0")),
        "{stats}"
    );
}

/// `--task K --of N` runs exactly the runs k with k mod N = K − 1; `--collect` refuses a partial
/// campaign (exit 2, naming the missing runs), then merges once every share is done.
#[test]
fn shares_partition_the_runs_and_collect_waits_for_all() {
    let dir = plan_dir(
        "scenario = \"rolling\"\n[set]\nduration = 0.05\n[sweep]\nslope_deg = [10.0, 15.0, 20.0, 25.0, 30.0]\n",
    );
    let o = campaign(
        dir.path(),
        &["plan.toml", "--out", "c", "--task", "2", "--of", "2"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let c = dir.path().join("c");
    let done: Vec<bool> = (0..5)
        .map(|k| c.join(format!("runs/{k:04}/summary.json")).is_file())
        .collect();
    assert_eq!(done, vec![false, true, false, true, false]);
    let o = campaign(dir.path(), &["plan.toml", "--out", "c", "--collect"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("3 of 5 runs are not finished (0000, 0002, 0004)"),
        "{}",
        text(&o)
    );
    let o = campaign(
        dir.path(),
        &["plan.toml", "--out", "c", "--task", "1", "--of", "2"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = campaign(dir.path(), &["plan.toml", "--out", "c", "--collect"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let table = std::fs::read_to_string(c.join("campaign.csv")).unwrap();
    assert_eq!(table.lines().count(), 6, "{table}");
}

/// Bad plans and options: one line naming the key (or run), exit 2, nothing run.
#[test]
fn bad_plans_are_refused_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &[&str], &str)] = &[
        (
            "scenario = \"rolling\"\n[sweep]\nfrction = [0.1, 0.2]\n",
            &[],
            "unknown key `frction`",
        ),
        (
            "scenario = \"rolling\"\n[sweep]\nseed = []\n",
            &[],
            "empty list",
        ),
        ("[sweep]\nseed = [1]\n", &[], "key `scenario` is missing"),
        (
            "scenario = \"rolling\"\n[sweep]\nfriction = [0.1, \"x\"]\n",
            &[],
            "run 0001",
        ),
        (
            "scenario = \"rolling\"\n[sweep]\nseed = [1]\n",
            &["--task", "3", "--of", "2"],
            "1 ≤ K ≤ N",
        ),
        (
            "scenario = \"rolling\"\n[sweep]\nseed = [1]\n",
            &["--task", "1"],
            "go together",
        ),
    ];
    for (k, (plan, extra, expect)) in cases.iter().enumerate() {
        let p = format!("plan{k}.toml");
        std::fs::write(dir.path().join(&p), plan).unwrap();
        let out = format!("out{k}");
        let mut args = vec![p.as_str(), "--out", out.as_str()];
        args.extend(extra.iter());
        let o = campaign(dir.path(), &args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "case {k}: {t}");
        assert!(t.contains(expect), "case {k}: expected `{expect}` in: {t}");
        assert_eq!(t.lines().count(), 1, "case {k}: one line: {t}");
        assert!(!dir.path().join(&out).join("runs/0000").exists());
    }
    // A campaign directory is bound to its plan.
    std::fs::write(
        dir.path().join("a.toml"),
        "scenario = \"rolling\"\n[set]\nduration = 0.02\n[sweep]\nseed = [1]\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("b.toml"),
        "scenario = \"rolling\"\n[set]\nduration = 0.03\n[sweep]\nseed = [1]\n",
    )
    .unwrap();
    assert_eq!(
        campaign(dir.path(), &["a.toml", "--out", "ab"])
            .status
            .code(),
        Some(0)
    );
    let o = campaign(dir.path(), &["b.toml", "--out", "ab"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("another plan"), "{}", text(&o));
}

/// Two seeds of a short shear cell merged into one μ(I) table: the points that passed their own
/// checks (`point_verdict` 0) of both runs and no other, a `run` column, and the grain diameter
/// of the merged table the mean of the runs' (to 1e-12).
#[test]
fn shear_cell_seeds_are_merged_and_fitted() {
    let dir = plan_dir(
        "scenario = \"shear-cell\"\n[set]\ngrains = 80\ncell_length_diameters = 10\ninertial_numbers = [0.02, 0.08, 0.3]\nleave_out = [\"mu-i\", \"mu-i-linear\", \"phi-i\"]\nstrain = 1.0\naverage_strain = 0.5\n[sweep]\nseed = [1, 2]\n",
    );
    let o = campaign(dir.path(), &["plan.toml", "--out", "c", "--jobs", "2"]);
    let t = text(&o);
    // 0: both laws fitted (perhaps in their linear forms); 3: one refused, with its reason.
    assert!(matches!(o.status.code(), Some(0) | Some(3)), "{t}");
    if o.status.code() == Some(3) {
        assert!(t.contains("refused"), "{t}");
    }
    let c = dir.path().join("c");
    let meta = |p: &Path| -> f64 {
        let s = std::fs::read_to_string(p).unwrap();
        s.lines()
            .find_map(|l| l.strip_prefix("# grain_diameter_m = "))
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    let d0 = meta(&c.join("runs/0000/rheology.csv"));
    let d1 = meta(&c.join("runs/0001/rheology.csv"));
    let dm = meta(&c.join("rheology.csv"));
    assert!(
        (dm - 0.5 * (d0 + d1)).abs() <= 1e-12 * dm,
        "{dm} vs {d0}, {d1}"
    );
    // rows of a table, and the value of its `point_verdict` column
    let rows = |p: &Path| -> Vec<(String, f64)> {
        let s = std::fs::read_to_string(p).unwrap();
        let mut lines = s.lines().filter(|l| !l.starts_with('#'));
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let j = head.iter().position(|h| *h == "point_verdict").unwrap();
        lines
            .map(|l| (l.to_string(), l.split(',').nth(j).unwrap().parse().unwrap()))
            .collect()
    };
    let mut expect = Vec::new();
    for k in 0..2 {
        for (l, v) in rows(&c.join(format!("runs/{k:04}/rheology.csv"))) {
            if v == 0.0 {
                expect.push(format!("{l},{k}"));
            }
        }
    }
    let merged: Vec<String> = rows(&c.join("rheology.csv"))
        .into_iter()
        .map(|r| r.0)
        .collect();
    assert_eq!(merged, expect);
    assert!(
        c.join("mu_i_law.json").is_file()
            || c.join("mu_i_linear_law.json").is_file()
            || t.contains("mu-i-linear: refused"),
        "{t}"
    );
}

/// `--collect` of a finished simple-shear campaign writes its figure, `rheology.png` (μ(I) and
/// φ(I) over every point with the merged laws), beside the merged table and the laws. The runs'
/// outputs are written here (three seeds, points on μ = 0.28 + I and φ = 0.80 − 0.25 I, one
/// point per run failed its own checks), so that only the collection runs.
#[test]
fn collect_writes_the_campaign_figure() {
    let dir = plan_dir("scenario = \"simple-shear\"\n[sweep]\nseed = [1, 2, 3]\n");
    let c = dir.path().join("c");
    for k in 0..3usize {
        let run = c.join(format!("runs/{k:04}"));
        std::fs::create_dir_all(&run).unwrap();
        std::fs::write(c.join(format!("runs/{k:04}.exit")), "0\n").unwrap();
        std::fs::write(run.join("summary.json"), "{\"verdict\": \"ok\"}\n").unwrap();
        let mut t = String::from(
            "# grain_diameter_m = 3e-3\n# grain_density_kg_m3 = 2.5e3\nI,I_std_error,mu,mu_std_error,phi,phi_std_error,P_Pa,point_verdict\n",
        );
        for (j, i) in [0.04, 0.07, 0.1, 0.15, 0.25].into_iter().enumerate() {
            let w = [0.004, -0.003, 0.001, -0.004, 0.002, 0.003, -0.001][(j + 2 * k) % 7];
            t.push_str(&format!(
                "{i},{},{},0.01,{},0.001,1000,{}\n",
                0.01 * i,
                0.28 + i + w,
                0.80 - 0.25 * i - 0.5 * w,
                u8::from(j == k + 1)
            ));
        }
        std::fs::write(run.join("rheology.csv"), t).unwrap();
    }
    assert!(!c.join("rheology.png").exists());
    let o = campaign(dir.path(), &["plan.toml", "--out", "c", "--collect"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    let png = std::fs::read(c.join("rheology.png")).unwrap_or_else(|e| panic!("{e}: {t}"));
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(t.contains("rheology.png"), "{t}");
    assert!(c.join("rheology.csv").is_file());
    assert!(
        c.join("mu_i_law.json").is_file() || c.join("mu_i_linear_law.json").is_file(),
        "{t}"
    );
}
