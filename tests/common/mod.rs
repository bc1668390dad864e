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

/// [`SMALL_SHEAR_CELL`] at the inertial numbers `list` (a TOML array), then `extra`.
pub fn small_shear_cell<'a>(list: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    SMALL_SHEAR_CELL
        .iter()
        .copied()
        .chain(std::iter::once(list))
        .chain(extra.iter().copied())
        .collect()
}
