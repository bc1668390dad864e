//! Settle the benchmark Janssen column: `cargo run --release -p grainlaw-core --example
//! janssen_column -- N [pour|deposit] [serial]`.
use grainlaw_core::benchmarks::{settle_column, ColumnRun, Preparation};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(2000);
    let prep = if args.get(1).is_some_and(|s| s == "pour") {
        Preparation::Pour
    } else {
        Preparation::Deposit
    };
    let mut run = ColumnRun::for_preparation(prep);
    if args.get(2).is_some_and(|s| s == "serial") {
        run.parallel = false;
    }
    if let Ok(v) = std::env::var("DT") {
        // a fixed step
        run.dt = v.parse().expect("DT");
        run.dt_range = [run.dt, run.dt];
    }
    if let Ok(v) = std::env::var("CAP") {
        run.max_sweeps = v.parse().expect("CAP");
    }
    match settle_column(n, prep, &run, 1) {
        Ok(r) => println!("{r:#?}\ntotal {:.2} s", r.total_seconds()),
        Err(e) => eprintln!("{e}"),
    }
}
