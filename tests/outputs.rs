//! Output writers: summary.json (flat, ordered, NaN → null), atomic files, VTK PolyData counts.

use grainlaw::output::vtk::{contacts_vtp, grains_vtp, walls_vtp};
use grainlaw::output::{OutputDir, Summary};

#[test]
fn summary_is_flat_ordered_json_with_null_for_non_finite() {
    let mut s = Summary::new();
    s.num("b", 1.5)
        .num("a", f64::NAN)
        .int("n", 3)
        .text("t", "x\"y")
        .flag("f", true)
        .num("b", 2.0);
    let v: serde_json::Value = serde_json::from_str(&s.to_json()).unwrap();
    assert_eq!(v["b"], 2.0);
    assert!(v["a"].is_null());
    assert_eq!(v["t"], "x\"y");
    let text = s.to_json();
    assert!(
        text.find("\"b\"").unwrap() < text.find("\"a\"").unwrap(),
        "insertion order kept"
    );
}

#[test]
fn output_dir_writes_atomically_and_removes_a_stale_summary() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("summary.json"), "{}").unwrap();
    let mut out = OutputDir::create(dir.path()).unwrap();
    assert!(
        !dir.path().join("summary.json").exists(),
        "a stale summary.json is removed at start"
    );
    out.write("sub/a.txt", b"hello").unwrap();
    assert_eq!(
        std::fs::read(dir.path().join("sub/a.txt")).unwrap(),
        b"hello"
    );
    let names: Vec<String> = std::fs::read_dir(dir.path().join("sub"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .collect();
    assert_eq!(names, vec!["a.txt".to_string()], "no temporary file left");
}

/// A settled rolling disk: one grain vertex, one contact line, one wall line.
#[test]
fn vtk_polydata_counts() {
    let l = grainlaw::scenarios::registry::load("rolling", &[]).unwrap();
    let c: grainlaw::scenarios::rolling::config::RollingConfig =
        grainlaw::scenarios::registry::config_of(&l).unwrap();
    let (mut w, _, _) = grainlaw::scenarios::rolling::build::rolling(&c).unwrap();
    for _ in 0..5 {
        w.step().unwrap();
    }
    let snap = w.snapshot();
    let g = grains_vtp(&snap).unwrap();
    assert!(g.contains("NumberOfPoints=\"1\" NumberOfVerts=\"1\""));
    for name in ["radius", "velocity", "stress", "inertia_ratio"] {
        assert!(g.contains(&format!("Name=\"{name}\"")), "{name}");
    }
    let c = contacts_vtp(&snap);
    assert!(
        c.contains("NumberOfPoints=\"2\" NumberOfVerts=\"0\" NumberOfLines=\"1\""),
        "{c}"
    );
    assert!(c.contains("Name=\"normal_force\""));
    let wl = walls_vtp(&snap);
    assert!(wl.contains("NumberOfLines=\"1\""));
}
