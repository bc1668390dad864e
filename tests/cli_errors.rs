//! Bad input gives one line on stderr naming the key, file or line, exit code 2, no panic, and
//! no `summary.json` (`docs/cli.md`).

mod common;

use common::grainlaw_in as grainlaw;

use std::path::Path;

/// Runs `args` and checks: exit code 2, nothing on stdout, exactly one line on stderr that starts
/// with `error:` and contains every `needle`, no panic message, no summary.json under `cwd`.
fn check_bad(args: &[&str], needles: &[&str], cwd: &Path) {
    let out = grainlaw(args, cwd);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(
        out.status.code(),
        Some(2),
        "{args:?}: exit {:?}, stderr {stderr}",
        out.status.code()
    );
    assert_eq!(
        lines.len(),
        1,
        "{args:?}: expected one line on stderr, got:\n{stderr}"
    );
    assert!(lines[0].starts_with("error: "), "{args:?}: {}", lines[0]);
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    for n in needles {
        assert!(
            lines[0].contains(n),
            "{args:?}: `{n}` not in `{}`",
            lines[0]
        );
    }
    assert!(
        out.stdout.is_empty(),
        "{args:?}: stdout {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let leftover: Vec<_> = common::walk(cwd)
        .into_iter()
        .filter(|p| p.ends_with("summary.json"))
        .collect();
    assert!(leftover.is_empty(), "{args:?}: left {leftover:?}");
}

#[test]
fn bad_scenario_input_is_one_line_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("broken.toml"),
        "scenario = \"rolling\"\nseed = 1\nslope_deg = [\n",
    )
    .unwrap();
    std::fs::write(
        d.join("extra.toml"),
        grainlaw::scenarios::registry::get("rolling")
            .unwrap()
            .builtin_toml()
            .to_string()
            + "\nwobble = 3\n",
    )
    .unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["run", "no-such-scenario"],
            &["unknown scenario `no-such-scenario`", "janssen"],
        ),
        (
            &["run", "--set", "grain.radius_mean=-1e-3"],
            &["grain.radius_mean", "> 0"],
        ),
        (
            &["run", "rolling", "--set", "radius=-0.01"],
            &["radius", "> 0"],
        ),
        (&["run", "rolling", "--set", "radius=0"], &["radius"]),
        (&["run", "--set", "grains.count=3"], &["grains"]),
        (
            &["run", "--set", "no_such_key=1"],
            &["unknown key `no_such_key`"],
        ),
        (
            &["run", "--set", "grain.radius=1"],
            &["unknown key `grain.radius`"],
        ),
        (&["run", "--set", "grains=many"], &["grains", "integer"]),
        (&["run", "--set", "grains=1.5"], &["grains", "integer"]),
        (&["run", "--set", "grain.density=nan"], &["grain.density"]),
        (&["run", "--set", "dt=inf"], &["dt"]),
        (&["run", "--set", "dt=0"], &["dt"]),
        (
            &["run", "--set", "friction.grain_wall=-0.1"],
            &["friction.grain_wall"],
        ),
        (
            &["run", "--set", "grain.radius_spread=2e-3"],
            &["grain.radius_spread"],
        ),
        (&["run", "rolling", "--set", "slope_deg=90"], &["slope_deg"]),
        (&["run", "rolling", "--set", "duration=-1"], &["duration"]),
        (
            &["run", "inclined-flow", "--set", "slope_deg=95"],
            &["slope_deg"],
        ),
        (&["run", "--set", "grains"], &["KEY=VALUE"]),
        (&["run", "--set", "grain=1"], &["grain", "table"]),
        (&["run", "missing.toml"], &["missing.toml"]),
        (&["run", "broken.toml"], &["broken.toml:3", "invalid TOML"]),
        (
            &["run", "extra.toml"],
            &["extra.toml", "unknown key `wobble`"],
        ),
        (&["run", "--bogus-flag"], &["--bogus-flag"]),
        (
            &["scenarios", "--show", "nope"],
            &["unknown scenario `nope`"],
        ),
    ];
    for (args, needles) in cases {
        check_bad(args, needles, d);
    }
}

#[test]
fn bad_files_for_fit_and_solve_fc_are_one_line_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("text.csv"),
        "I,mu\n0.01,0.3\n0.02,abc\n0.05,0.35\n0.1,0.4\n0.2,0.45\n",
    )
    .unwrap();
    std::fs::write(d.join("short.csv"), "I,mu\n0.01,0.3\n").unwrap();
    std::fs::write(d.join("nocol.csv"), "x,y\n1,2\n3,4\n").unwrap();
    std::fs::write(
        d.join("trunc.json"),
        "{\"format\": \"fc-problem-v1\", \"dimension\": 2, \"nc\": 1, \"mu\": [0.3], \"q\": [",
    )
    .unwrap();
    std::fs::write(
        d.join("negmu.json"),
        r#"{"format":"fc-problem-v1","dimension":2,"nc":1,"mu":[-0.3],"q":[-1,0],"W":{"storage":"dense","data":[[1,0],[0,3]]}}"#,
    )
    .unwrap();
    std::fs::write(
        d.join("size.json"),
        r#"{"format":"fc-problem-v1","dimension":2,"nc":2,"mu":[0.3,0.3],"q":[-1,0],"W":{"storage":"dense","data":[[1,0],[0,3]]}}"#,
    )
    .unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (&["fit", "mu-i", "absent.csv"], &["absent.csv"]),
        (&["fit", "mu-i", "text.csv"], &["text.csv", "3"]),
        (&["fit", "mu-i", "short.csv"], &["short.csv", "too few"]),
        (&["fit", "mu-i", "nocol.csv"], &["nocol.csv"]),
        (&["fit", "no-such-law", "text.csv"], &["no-such-law"]),
        (&["solve-fc", "absent.json"], &["absent.json"]),
        (&["solve-fc", "trunc.json"], &["trunc.json", "line 1"]),
        (&["solve-fc", "negmu.json"], &["negmu.json", "key `mu[0]`"]),
        (&["solve-fc", "size.json"], &["size.json", "key `q`"]),
        (&["solve-fc", "negmu.json", "--tol", "-1"], &["--tol"]),
    ];
    for (args, needles) in cases {
        check_bad(args, needles, d);
    }
}
