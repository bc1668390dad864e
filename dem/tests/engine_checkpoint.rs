//! A run resumed from a checkpoint is bit-identical to an uninterrupted run.

mod common;

use dem::checkpoint::{read_checkpoint, write_checkpoint};

fn bits(w: &dem::World) -> Vec<u64> {
    w.bodies
        .iter()
        .flat_map(|b| {
            [
                b.position.x.to_bits(),
                b.position.y.to_bits(),
                b.velocity.x.to_bits(),
                b.velocity.y.to_bits(),
                b.angle.to_bits(),
                b.omega.to_bits(),
            ]
        })
        .collect()
}

#[test]
fn resume_from_checkpoint_is_bit_identical() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("world.ckpt.json.gz");
    let make = || {
        let mut w = common::random_box(120, 0.1, 0.003, 0.005, 0.4, 1.0, 21);
        w.params.dt = 5e-4;
        w.params.solver.tolerance = 1e-6;
        w.params.solver.max_iterations = 3000;
        w
    };
    // Uninterrupted.
    let mut a = make();
    for _ in 0..300 {
        a.step().unwrap();
    }
    // Interrupted after 137 steps (mid-collapse, contacts warm-started), resumed from disk.
    let mut b = make();
    for _ in 0..137 {
        b.step().unwrap();
    }
    write_checkpoint(&b, &path).unwrap();
    drop(b);
    let mut c = read_checkpoint(&path).unwrap();
    assert_eq!(c.step_index, 137);
    for _ in 137..300 {
        c.step().unwrap();
    }
    assert_eq!(bits(&a), bits(&c));
    assert_eq!(a.time.to_bits(), c.time.to_bits());
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn unreadable_checkpoints_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.gz");
    std::fs::write(&path, b"not gzip").unwrap();
    let e = read_checkpoint(&path).unwrap_err().to_string();
    assert!(e.contains("bad.gz"), "{e}");
    assert!(read_checkpoint(&dir.path().join("missing")).is_err());
}
