"""Snapshots of another code from Python: the committed 2D LAMMPS run (152 disks settling in a
box, datasets/external/lammps) read as ``grainlaw homogenise --from lammps`` reads it."""

import pathlib

import numpy as np
import pytest

import grainlaw

LAMMPS = pathlib.Path(__file__).resolve().parents[2] / "datasets" / "external" / "lammps"


def lammps_files():
    return sorted(str(p) for p in LAMMPS.glob("*.dump.gz"))


def test_lammps_snapshots_are_read_with_their_ids_and_accelerations():
    snaps = grainlaw.read_snapshots("lammps", lammps_files())
    assert [s["snapshot"].step for s in snaps] == [400000, 400001, 400002]
    for s in snaps:
        ids = s["grain_ids"]
        assert len(ids) == 152 and len(set(ids.tolist())) == 152
        # the dumps carry fx, fy, tqz: the accelerations come from the file
        assert s["accelerations"] == "file"
        # times from the dumps (dump_modify time yes): step × 2e-6 s
        assert abs(s["snapshot"].time - s["snapshot"].step * 2e-6) <= 1e-9


def test_total_grain_stress_is_symmetric_with_the_file_accelerations():
    # moment balance of each grain: the inertia part (ω̇ = τ/I from the dumped torque) cancels
    # the skew part of the contact part, up to the lever difference between LAMMPS' torque
    # (at R) and the mid-overlap contact point (R − δ/2), δ/R ~ 1e-4 here: 1e-3 of |Σ_c|
    snaps = grainlaw.read_snapshots("lammps", lammps_files())
    for s in snaps:
        g = grainlaw.grain_stresses(s["snapshot"])
        total, contact = g["total"], g["contact"]
        skew = 0.5 * np.abs(total[:, 0, 1] - total[:, 1, 0])
        norm = np.sqrt((contact**2).sum(axis=(1, 2)))
        assert np.all(skew <= 1e-3 * norm)
        # and it is the inertia part that makes it so: the contact part alone is more skew
        contact_skew = 0.5 * np.abs(contact[:, 0, 1] - contact[:, 1, 0])
        assert contact_skew.sum() > 10.0 * skew.sum()


def test_unknown_format_and_unreadable_file_are_input_errors(tmp_path):
    with pytest.raises(grainlaw.InputError):
        grainlaw.read_snapshots("yade", lammps_files())
    bad = tmp_path / "atoms.1.dump"
    bad.write_text("ITEM: TIMESTEP\nnot a number\n")
    with pytest.raises(grainlaw.InputError, match="atoms.1.dump"):
        grainlaw.read_snapshots("lammps", [str(bad)])
