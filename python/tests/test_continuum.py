"""grainlaw.continuum: a calibrated μ(I) law run in Gerris (skipped, saying so, without
gerris2D), its refusals as the package's exceptions, and docs/continuum.md's worked reading of
the law JSON in Python against the Rust evaluation."""

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

import grainlaw

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "tests" / "fixtures" / "continuum"
LINEAR = FIXTURES / "simple_shear_mu_i_law.json"
SATURATING = FIXTURES / "lagree2011_mu_i_law.json"
needs_gerris = pytest.mark.skipif(
    shutil.which("gerris2D") is None, reason="gerris2D is not installed (apt-get install gerris)"
)


def worked_python_block():
    """The code block after the `worked-python` marker of docs/continuum.md."""
    doc = (ROOT / "docs" / "continuum.md").read_text()
    rest = doc[doc.index("<!-- worked-python"):]
    body = rest[rest.index("```"):]
    body = body[body.index("\n") + 1:]
    return body[: body.index("```")]


def test_worked_reading_in_python_matches_the_rust_evaluation():
    namespace = {}
    exec(worked_python_block(), namespace)
    I = np.geomspace(1e-3, 2.0, 13)
    for path in (SATURATING, LINEAR):
        f = namespace["law_function"](str(path))
        rust = grainlaw.load_law(path).evaluate(I)
        python = np.array([f(i) for i in I])
        assert np.all(np.abs(python - rust) <= 1e-12 * np.abs(rust)), (path.name, python - rust)


@needs_gerris
def test_inclined_plane_matches_bagnold(tmp_path):
    r = grainlaw.continuum(
        "inclined-plane", LINEAR, tmp_path / "plane", slope_deg=26.0, packing_fraction=0.75
    )
    assert r["verdict"] == "ok"
    p = r["profile"]
    u, ub = p["velocity_gerris_m_s"], p["velocity_bagnold_m_s"]
    assert u.size == 64
    # level 6: within 0.5 % of the surface velocity (as tests/continuum.rs)
    assert np.max(np.abs(u - ub)) < 5e-3 * ub.max()
    assert r["summary"]["max_relative_error_vs_bagnold"] < 5e-3
    assert (tmp_path / "plane" / "gerris" / "inclined.gfs").is_file()


@needs_gerris
def test_column_collapse_against_staron(tmp_path):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        r = grainlaw.continuum(
            "column-collapse",
            SATURATING,
            tmp_path / "col",
            dem=FIXTURES / "staron2005",
            packing_fraction=1.0,
            level=7,
        )
    assert r["verdict"] == "ok"
    # the run's I leaves the law's range near the surface: a warning, not an error
    assert any("calibrated range" in str(x.message) for x in w)
    assert r["warnings"]
    front = r["front"]
    assert front["t_star"][0] == 0.0 and np.all(np.diff(front["t_star"]) > 0)
    assert set(r["profiles"]) == {"t0.66", "t0.95", "t1.24", "t1.52", "t2.28", "end"}
    rows = r["comparison"]["rows"]
    assert len(rows) == 5
    assert all(abs(row["x_f_relative_difference"]) < 0.12 for row in rows)


def test_refusals_raise_the_package_exceptions(tmp_path):
    with pytest.raises(grainlaw.InputError, match="not a μ"):
        grainlaw.continuum(
            "column-collapse", FIXTURES / "simple_shear_phi_i_law.json", tmp_path / "a",
            packing_fraction=0.8,
        )
    with pytest.raises(grainlaw.InputError, match="packing-fraction"):
        grainlaw.continuum("column-collapse", LINEAR, tmp_path / "b")
    with pytest.raises(grainlaw.InputError, match="no steady flow"):
        grainlaw.continuum(
            "inclined-plane", LINEAR, tmp_path / "c", slope_deg=10.0, packing_fraction=0.8
        )
    with pytest.raises(grainlaw.InputError, match="case"):
        grainlaw.continuum("dam-break", LINEAR, tmp_path / "d")
    with pytest.raises(grainlaw.SolverError, match="not found") as e:
        grainlaw.continuum(
            "column-collapse", LINEAR, tmp_path / "e", packing_fraction=0.8, level=6,
            gerris="/nonexistent/gerris2D",
        )
    assert "the case is left in" in str(e.value)
    assert (tmp_path / "e" / "gerris" / "column.gfs").is_file()
