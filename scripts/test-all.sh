#!/usr/bin/env bash
# The project's test command: the Rust tests, then the Python package (python/, PyO3 + maturin)
# built into a fresh virtual environment, its tests and the examples in examples/python.
#
# Needs cargo and python3 (with venv and pip); maturin, numpy and pytest come from PyPI. The
# package is built in the same cargo target directory as the workspace (CARGO_TARGET_DIR, or
# target/), so the crates it shares with it are compiled once. GRAINLAW_VENV chooses the
# virtual environment's directory (default: TARGET/py-venv, made anew each time).
set -euo pipefail
cd "$(dirname "$0")/.."

cargo test --release --workspace
# The compile-only 3D skeleton behind dem's `dim3` feature (its cone, frame and sphere tests).
cargo test --release -p dem --features dim3 --lib dim3

# The CLI the Python tests compare with (same seed, same summary.json).
cargo build --release --bin grainlaw
target_dir="${CARGO_TARGET_DIR:-$PWD/target}"
export CARGO_TARGET_DIR="$target_dir"
export GRAINLAW_BIN="$target_dir/release/grainlaw"

venv="${GRAINLAW_VENV:-$target_dir/py-venv}"
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check ./python numpy pytest
"$venv/bin/python" -m pytest python/tests -q -p no:cacheprovider
