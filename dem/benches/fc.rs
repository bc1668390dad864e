//! Criterion benchmarks of the standalone frictional-contact solver on the reference problems
//! of `datasets/fc-problems/` (tolerance 1e-6 from r = 0), and the raw cost of one plain
//! Gauss–Seidel sweep (throughput in contact updates per second).
//!
//! `cargo bench -p dem --bench fc`; the summary table beside Siconos is the
//! root package's `cargo bench --bench fc_table`.

use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use dem::fc::{nsgs::sweep_rate, read_problem, solve, FcOptions};

const PROBLEMS: &[&str] = &[
    "piles/pile_pert_1000",
    "siconos-2d/fc2d_granularflowonwall_02020_00213",
    "siconos-2d/fc2d_granularflowonwall_07002_00801",
    "large/pile_pert_10000",
];

fn path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../datasets/fc-problems/{name}.json.gz"))
}

fn solve_reference(c: &mut Criterion) {
    let mut g = c.benchmark_group("fc_solve");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    for name in PROBLEMS {
        let p = read_problem(path(name)).expect("reference problem");
        let options = FcOptions::default();
        let s = solve(&p, &options).expect("solve");
        assert!(s.converged, "{name}: error {:e}", s.error);
        g.bench_with_input(BenchmarkId::from_parameter(name), &p, |b, p| {
            b.iter(|| solve(p, &options).expect("solve"))
        });
    }
    g.finish();
}

fn one_sweep(c: &mut Criterion) {
    let mut g = c.benchmark_group("fc_sweep");
    for name in PROBLEMS {
        let p = read_problem(path(name)).expect("reference problem");
        let nc = p.contacts();
        g.throughput(Throughput::Elements(nc as u64));
        g.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter_custom(|iters| {
                let iters = iters.max(1) as usize;
                Duration::from_secs_f64((nc * iters) as f64 / sweep_rate(&p, iters))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, solve_reference, one_sweep);
criterion_main!(benches);
