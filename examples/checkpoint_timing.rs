//! Times the run checkpoint of a large world: a deposit lattice of `N` disks (default 10⁶) on a
//! floor between two walls, one step taken so that every lattice contact carries an impulse,
//! then the checkpoint written as a run writes it (`grainlaw::checkpoint::write`: JSON, gzip,
//! temporary file, fsync, rename), with the parts timed apart.
//!
//! `cargo run --release --example checkpoint_timing -- [N]`

use std::io::{BufWriter, Write};
use std::time::Instant;

use dem::{ContactLaws, SolverParams, World, WorldParams};
use grainlaw::checkpoint::{self, Cursor, PhasePlan, RunCheckpoint, ScenarioRecord};
use grainlaw::provenance::RunOrigin;
use grainlaw::scenarios::common::Stop;
use grainlaw::scenarios::phases::PhaseProgress;
use nalgebra::Vector2;

/// A triangular lattice of `n` disks of radius about `r` (1 mm, scaled down by up to 1 %), rows
/// `√3 r` apart, `cols` per row, so that neighbours touch within the detection gap.
fn lattice(n: usize, cols: usize) -> World {
    let r = 1e-3;
    let params = WorldParams {
        dt: 2e-4,
        theta: 1.0,
        gravity: Vector2::new(0.0, -9.81),
        periodic_x: None,
        detection_gap: 0.1 * r,
        overlap_rate: 1e-4,
        position_correction: true,
        solver: SolverParams {
            tolerance: 1e-4,
            max_iterations: 20,
            ..Default::default()
        },
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.3));
    let width = 2.0 * r * (cols as f64 + 0.5);
    w.add_box_walls(width, 0);
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in 0..n {
        let (ix, iy) = (i % cols, i / cols);
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let u = (s >> 11) as f64 / (1u64 << 53) as f64;
        let x = r * (1.0 + 2.0 * ix as f64 + (iy % 2) as f64);
        let y = r * (1.0 + 3f64.sqrt() * iy as f64);
        w.add_grain(Vector2::new(x, y), r * (1.0 - 0.01 * u), 2500.0, 0);
    }
    w
}

/// CPU seconds (user + system, all threads) of this process so far, from `/proc/self/stat`
/// (Linux; 0 elsewhere). On a shared machine the wall-clock time of a phase depends on the
/// load; its CPU time does not.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| f.get(k).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    // utime and stime are fields 14 and 15 of the file, 12 and 13 after the name and state.
    (ticks(11) + ticks(12)) / 100.0
}

/// A writer that only counts bytes.
struct Counter(usize);

impl Write for Counter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len();
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let cols = (n as f64).sqrt().ceil() as usize;
    let t = Instant::now();
    let mut w = lattice(n, cols);
    w.step().expect("one step");
    println!(
        "world: {n} grains, {} contacts, built and stepped once in {:.1} s",
        w.contacts().rows.len(),
        t.elapsed().as_secs_f64()
    );
    let dir = std::env::temp_dir().join(format!("grainlaw-cp-timing-{}", std::process::id()));
    let (t, c) = (Instant::now(), cpu_seconds());
    let cp = RunCheckpoint {
        format: checkpoint::FORMAT.to_string(),
        grainlaw_version: env!("CARGO_PKG_VERSION").to_string(),
        scenario: ScenarioRecord {
            name: "lattice".into(),
            source: "example".into(),
            effective_toml: String::new(),
            sets: Vec::new(),
            allow_suspect: false,
        },
        cursor: Cursor {
            phase: 0,
            plan: PhasePlan {
                name: "lattice".into(),
                stop: Stop::Steps(1),
            },
            progress: PhaseProgress::default(),
        },
        steps_total: 1,
        wall_seconds: 0.0,
        origin: RunOrigin::default(),
        world: w.state(),
        state: (),
    };
    let (t_state, c_state) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let (t, c) = (Instant::now(), cpu_seconds());
    let mut json = Counter(0);
    serde_json::to_writer(BufWriter::with_capacity(1 << 20, &mut json), &cp).expect("serialise");
    let (t_json, c_json) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let path = checkpoint::file_of(&dir);
    let (t, c) = (Instant::now(), cpu_seconds());
    checkpoint::write(&path, &cp).expect("checkpoint written");
    let (t_write, c_write) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let size = std::fs::metadata(&path).map_or(0, |m| m.len());
    println!(
        "wall (CPU) seconds: world state copied {t_state:.2} ({c_state:.2}); JSON alone, {:.1} MB: {t_json:.2} ({c_json:.2}); checkpoint::write (JSON + parallel gzip + temporary file + fsync + rename): {t_write:.2} ({c_write:.2}), {:.1} MB on {} threads",
        json.0 as f64 / 1e6,
        size as f64 / 1e6,
        rayon::current_num_threads()
    );
    let (t, c) = (Instant::now(), cpu_seconds());
    let back: RunCheckpoint<serde::de::IgnoredAny> = checkpoint::read(&dir).expect("read back");
    println!(
        "read back in {:.2} s ({:.2} s CPU; {} bodies)",
        t.elapsed().as_secs_f64(),
        cpu_seconds() - c,
        back.world.bodies.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
