"""The examples in examples/python run and print what they promise."""

import re
import subprocess
import sys
from pathlib import Path

import grainlaw

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "python"


def run_example(name, cwd, *args):
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *args], cwd=cwd, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_janssen_pipeline_refits_the_runs_own_k(tmp_path):
    out = run_example("janssen_pipeline.py", tmp_path, "140")
    m = re.search(r"K\s+= (\d+\.\d+)\s+\(95 % CI (\d+\.\d+) … (\d+\.\d+)\); the run's own fit: (\d+\.\d+)", out)
    assert m, out
    k, lo, hi, run_k = (float(x) for x in m.groups())
    # 140 grains: a suspect run (the CLI exits 3), said before any number and at the number
    assert "verdict: suspect" in out and "NOT a calibrated law" in out, out
    assert "the fit's own verdict: ok" in out
    # the profile CSV holds the run's numbers exactly, so the refit is the run's fit
    assert k == run_k
    assert lo < k < hi


def test_mu_i_fit_prints_the_law_and_the_refusal(tmp_path):
    out = run_example("mu_i_fit.py", tmp_path)
    values = dict(re.findall(r"^(\w+)\s*= (\d+\.\d+)", out, re.M))
    # generated with μ_s = 0.38, μ_2 = 0.64, I_0 = 0.28 and noise 0.004
    assert abs(float(values["mu_s"]) - 0.38) < 0.02
    assert abs(float(values["mu_2"]) - 0.64) < 0.05
    assert "refused:" in out and "suggestion: use mu-i-linear" in out
    assert "verdict: ok" in out
    law = grainlaw.load_law(tmp_path / "mu_i_law.json")
    assert law.name == "mu-i"
