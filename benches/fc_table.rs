//! Prints the reference benchmark table (`cargo bench --bench fc_table [DIR]`): every
//! problem of `datasets/fc-problems/` solved at tolerance 1e-6 from r = 0, beside Siconos 4.4
//! NSGS measured on the development machine.

use std::path::PathBuf;

fn main() {
    let dir = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("datasets/fc-problems"));
    match grainlaw::fc_bench::run_reference_benchmarks(&dir) {
        Ok(rows) => print!("{}", grainlaw::fc_bench::format_table(&rows)),
        Err(e) => {
            eprintln!("fc_table: {e}");
            std::process::exit(2);
        }
    }
}
