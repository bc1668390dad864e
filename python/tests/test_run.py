"""Scenario runs from Python: the same summary as the command line, bit for bit, and the
tables and laws as arrays and Law objects."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import grainlaw

# A small Janssen column: a few seconds per run.
SMALL = {"grains": 140, "relax.max_time": 0.3, "release.floor_drop": 1e-4}


def cli_binary():
    """The `grainlaw` executable: $GRAINLAW_BIN, else the repository's release build."""
    env = os.environ.get("GRAINLAW_BIN")
    if env:
        return env
    root = Path(__file__).resolve().parents[2]
    target = Path(os.environ.get("CARGO_TARGET_DIR", root / "target"))
    exe = target / "release" / "grainlaw"
    return str(exe) if exe.exists() else shutil.which("grainlaw")


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("py") / "janssen"
    return grainlaw.run("janssen", overrides=SMALL, out=out), out


def test_summary_matches_the_cli_bit_for_bit(small_run, tmp_path):
    exe = cli_binary()
    if exe is None:
        pytest.skip("no grainlaw executable: set GRAINLAW_BIN or run `cargo build --release`")
    result, _ = small_run
    out = tmp_path / "cli"
    sets = [a for k, v in SMALL.items() for a in ("--set", f"{k}={v!r}")]
    subprocess.run([exe, "run", "janssen", "--out", str(out), "-q", *sets], check=True)
    cli = json.loads((out / "summary.json").read_text())
    py = result["summary"]
    assert list(cli) == list(py)
    for key in cli:
        if key == "wall_seconds":
            continue
        # the same numbers, not close ones: same seed, same code, same floating-point order
        assert cli[key] == py[key], key
    # the CSV profiles too
    for name in ("wall_profile.csv", "history.csv"):
        assert (out / name).read_bytes() == (Path(result["out"]) / name).read_bytes(), name


def test_run_returns_tables_and_the_calibrated_law(small_run):
    result, out = small_run
    s = result["summary"]
    assert s["scenario"] == "janssen" and s["seed"] == 1
    assert result["out"] == str(out)
    prof = result["tables"]["wall_profile"]
    assert isinstance(prof["z_m"], np.ndarray)
    n = prof["z_m"].size
    assert n > 0 and all(v.shape == (n,) for v in prof.values())
    # depths increase down the column, and σ_v is compressive (positive) there
    assert np.all(np.diff(prof["z_m"]) > 0)
    # the law written by the run is the one summarised, read back exactly
    law = result["laws"]["janssen_law"]
    assert result["verdict"] == s["verdict"] == law.verdict == "ok"
    assert law["K"] == s["janssen_K"]
    lo, hi = law.intervals["K"]
    assert lo == s["janssen_K_ci_low"] and hi == s["janssen_K_ci_high"]


def test_a_refused_run_raises_with_its_verdict_and_result(tmp_path):
    # 30 grains: too short a column for Janssen's law; the CLI exits 3 (refused)
    out = tmp_path / "refused"
    with pytest.raises(grainlaw.ResultRefused) as info:
        grainlaw.run("janssen", overrides={**SMALL, "grains": 30}, out=out)
    e = info.value
    assert isinstance(e, grainlaw.GrainlawError)
    assert e.verdict == "refused"
    assert any(r["check"] == "janssen.fit" and r["verdict"] == "refused" for r in e.reasons), e.reasons
    assert "janssen.fit (refused)" in str(e)
    # the result is there, every file written, its law rejected, not calibrated
    assert e.result["verdict"] == "refused"
    assert e.result["summary"]["verdict"] == "refused"
    assert e.result["verdict_reasons"] == e.reasons
    assert not e.result["laws"]
    assert (out / "summary.json").exists()
    # allow_suspect does not let a refused run through
    with pytest.raises(grainlaw.ResultRefused):
        grainlaw.run("janssen", overrides={**SMALL, "grains": 30}, allow_suspect=True)


def test_a_suspect_run_raises_unless_allowed(tmp_path):
    # 140 grains without the quick relaxation: the CLI calls it suspect and exports no law
    # (solver.sensitivity_janssen)
    out = tmp_path / "suspect"
    with pytest.raises(grainlaw.ResultSuspect) as info:
        grainlaw.run("janssen", overrides={"grains": 140}, out=out)
    e = info.value
    assert e.verdict == "suspect" and e.reasons
    assert all(r["verdict"] == "suspect" for r in e.reasons), e.reasons
    assert "allow_suspect=True" in str(e)
    assert not e.result["laws"] and "janssen_law" in e.result["rejected_laws"]
    assert e.result["rejected_laws"]["janssen_law"].verdict == "suspect"
    # allowed: returned, the law exported and marked suspect, as `--allow-suspect`
    result = grainlaw.run("janssen", overrides={"grains": 140}, out=out, allow_suspect=True)
    assert result["verdict"] == "suspect"
    law = result["laws"]["janssen_law"]
    assert law.verdict == "suspect"
    assert [r["check"] for r in law.verdict_reasons] == [r["check"] for r in e.reasons]
    assert not result["rejected_laws"], "the stale rejected law is removed"


def test_run_without_out_uses_a_removed_temporary_directory():
    result = grainlaw.run("rolling", overrides={"duration": 0.1})
    assert result["out"] is None
    assert result["summary"]["scenario"] == "rolling"
    assert result["tables"], "the tables are read before the directory is removed"


def test_bad_scenario_and_override_are_input_errors():
    with pytest.raises(grainlaw.InputError, match="no_such"):
        grainlaw.run("no_such_scenario")
    with pytest.raises(grainlaw.InputError, match="grians"):
        grainlaw.run("janssen", overrides={"grians": 10})
    with pytest.raises(grainlaw.InputError):
        grainlaw.run("janssen", overrides={"grains": "many"})


def test_scenarios_lists_the_builtins():
    names = grainlaw.scenarios()
    assert {"janssen", "rolling", "shear-cell"} <= set(names)


def test_ctrl_c_stops_the_run_after_a_step_with_a_checkpoint(tmp_path):
    out = tmp_path / "janssen"
    code = f"import grainlaw; grainlaw.run('janssen', out={str(out)!r})"
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    # scenario.toml is written before the first step
    while not (out / "scenario.toml").exists():
        assert proc.poll() is None, proc.stderr.read()
        assert time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode != 0
    assert "KeyboardInterrupt" in err and "--resume" in err, err
    assert (out / "checkpoint" / "run.json.gz").exists()
    assert not (out / "summary.json").exists()
