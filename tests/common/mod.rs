//! Run arguments shared by the command-line tests.
#![allow(dead_code)]

/// `grainlaw run shear-cell -q` on a small cell: 60 grains, 10 diameters long, short runs
/// (strain 0.6, the last 0.3 averaged) after a 0.05 s compression, about a second; the target
/// inertial numbers follow as `--set inertial_numbers=[…]`.
pub const SMALL_SHEAR_CELL: &[&str] = &[
    "run",
    "shear-cell",
    "-q",
    "--set",
    "grains=60",
    "--set",
    "cell_length_diameters=10",
    "--set",
    "strain=0.6",
    "--set",
    "average_strain=0.3",
    "--set",
    "compression_time=0.05",
    "--set",
];

/// The laws a rheology of three inertial numbers cannot identify (μ(I) needs 5, its linear
/// form and φ(I) 4: `datasets::config::laws`), left out so that such a plan runs.
pub const LEAVE_OUT_RHEOLOGY: &str = r#"leave_out=["mu-i", "mu-i-linear", "phi-i"]"#;

/// [`SMALL_SHEAR_CELL`] at the three inertial numbers `list` (a TOML array) with the laws they
/// cannot identify left out ([`LEAVE_OUT_RHEOLOGY`]: the wall law is still fitted), then
/// `extra`.
pub fn small_shear_cell<'a>(list: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    SMALL_SHEAR_CELL
        .iter()
        .copied()
        .chain([list, "--set", LEAVE_OUT_RHEOLOGY])
        .chain(extra.iter().copied())
        .collect()
}
