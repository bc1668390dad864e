"""Snapshots of another code from Python: the committed 2D LAMMPS run (152 disks settling in a
box, datasets/external/lammps) read as ``grainlaw homogenise --from lammps`` reads it."""

import json
import pathlib
import subprocess

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


def homogenise_args(out):
    return ["homogenise", "--from", "lammps", "--mu", "0.5", "-q", "--out", str(out), *lammps_files()]


def test_homogenise_writes_what_the_cli_writes(tmp_path):
    """``grainlaw.homogenise`` is ``grainlaw homogenise --from``: the same files, the same
    summary.json bit for bit (but wall_seconds), the same CSV bytes; and the walls of the settled
    column carry its weight."""
    out = tmp_path / "py"
    r = grainlaw.homogenise("lammps", lammps_files(), out=out, mu=0.5)
    assert r["out"] == str(out)
    files = r["files"]
    # every file written is listed once with its path, summary.json last; nothing else is left
    assert list(files)[-1] == "summary.json"
    on_disk = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    assert on_disk == sorted(files)
    for name, path in files.items():
        assert pathlib.Path(path) == out / name and pathlib.Path(path).stat().st_size > 0
    # CSV per snapshot, figures, a VTK frame per snapshot
    for step in (400000, 400001, 400002):
        assert f"grains_{step}.csv" in files
    for name in ("snapshots.csv", "walls.csv", "coarse.csv", "stress_profile.csv", "mobilisation.csv",
                 "grains.png", "stress_profile.png", "grains.pvd", "contacts.pvd", "walls.pvd"):
        assert name in files, name
    for kind in ("grains", "contacts", "walls"):
        assert [f"vtk/{kind}_{k:04d}.vtp" for k in range(3)] == [f for f in files if f.startswith(f"vtk/{kind}_")]
    assert (out / "grains.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    s = r["summary"]
    assert s["command"] == "homogenise" and s["snapshots"] == 3 and s["grains"] == 152
    # the weight of the 152 disks (Σ m g, masses from the dump) is carried by the walls to 2 %
    # (the column is still settling: kinetic energy 6e-8 J)
    snap = grainlaw.read_snapshots("lammps", lammps_files())[-1]["snapshot"]
    weight = 9.81 * snap.masses[snap.is_grain].sum()
    carried = -sum(s[f"wall_{w}_force_y_N"] for w in s["walls"])
    assert abs(carried - weight) < 0.02 * weight, (carried, weight)

    from test_run import cli_binary

    exe = cli_binary()
    if exe is None:
        pytest.skip("no grainlaw executable: set GRAINLAW_BIN or run `cargo build --release`")
    cli_out = tmp_path / "cli"
    subprocess.run([exe, *homogenise_args(cli_out)], check=True)
    cli = json.loads((cli_out / "summary.json").read_text())
    assert list(cli) == list(s)
    for key in cli:
        if key != "wall_seconds":
            # the same numbers, not close ones: the same Rust function on the same files
            assert cli[key] == s[key], key
    for name in ("snapshots.csv", "grains_400002.csv", "walls.csv", "coarse.csv"):
        assert (cli_out / name).read_bytes() == (out / name).read_bytes(), name
    assert sorted(str(p.relative_to(cli_out)) for p in cli_out.rglob("*") if p.is_file()) == on_disk


def test_homogenise_refuses_bad_input(tmp_path):
    bad = tmp_path / "atoms.1.dump"
    bad.write_text("ITEM: TIMESTEP\nnot a number\n")
    with pytest.raises(grainlaw.InputError, match="atoms.1.dump"):
        grainlaw.homogenise("lammps", [str(bad)], out=tmp_path / "o")
    with pytest.raises(grainlaw.InputError, match="mu"):
        grainlaw.homogenise("lammps", lammps_files(), out=tmp_path / "o", mu=-1.0)
    with pytest.raises(grainlaw.InputError, match="not a directory"):
        grainlaw.homogenise("lammps", lammps_files(), out=bad)
    # nothing was written by the refused calls
    assert not (tmp_path / "o").exists()


def test_homogenise_a_real_lmgc90_run(tmp_path):
    """The files LMGC90 wrote (datasets/external/lmgc90/real, 36 disks settled in a box of three
    JONCx walls): the wall forces of summary.json are LMGC90's own reactions `Reac_` to the 7
    digits of its files, and the walls carry the disks' weight (m = ρ π R², ρ = 2500 kg/m³)."""
    real = LAMMPS.parent / "lmgc90" / "real"
    files = [str(real / f) for f in ("BODIES.DAT", "DOF.OUT.1", "DOF.OUT.2", "Vloc_Rloc.OUT.1", "Vloc_Rloc.OUT.2")]
    r = grainlaw.homogenise("lmgc90", files, out=tmp_path / "o", density=2500.0, mu=0.3)
    s = r["summary"]
    assert s["snapshots"] == 2 and s["step"] == 400 and s["grains"] == 36
    ref = np.loadtxt(real / "lmgc90_reference_2.csv", delimiter=",", skiprows=2)
    scale = np.hypot(ref[:, 4], ref[:, 5]).max()
    for body in (1, 2, 3):
        row = ref[ref[:, 0] == body][0]
        assert abs(s[f"wall_body{body}_force_x_N"] - row[4]) < 1e-6 * scale
        assert abs(s[f"wall_body{body}_force_y_N"] - row[5]) < 1e-6 * scale
    snap = grainlaw.read_snapshots("lmgc90", files, density=2500.0)[-1]["snapshot"]
    radii = snap.radii[snap.is_grain]
    weight = 9.81 * (2500.0 * np.pi * radii**2).sum()
    carried = -sum(s[f"wall_{w}_force_y_N"] for w in s["walls"])
    assert abs(carried - weight) < 1e-5 * weight, (carried, weight)


RVE = LAMMPS.parent / "lammps-rve"


def test_a_tilted_biperiodic_lammps_cell_is_read_as_lammps_computes_it():
    """A snapshot of the LAMMPS simple shear (datasets/external/lammps-rve/exact, a tilted
    triclinic cell periodic in x and y, written at the setup of a `run 0`): the cell from the
    dump header, the pairs' minimum images across the tilt, and the whole-sample means over
    the cell's area, as `compute stress/atom NULL pair` and the cell's volume say."""
    files = sorted(str(p) for p in (RVE / "exact").glob("*.I0.003.*.dump.gz"))
    (s,) = grainlaw.read_snapshots("lammps", files)
    snap = s["snapshot"]
    cell = snap.cell
    assert cell is not None and snap.periodic_x is None
    step, time, sxx, syy, sxy, lx, ly, xy, area = np.loadtxt(RVE / "exact" / "thermo_I0.003.txt", skiprows=1)
    np.testing.assert_allclose(cell["h"], [[lx, xy], [0.0, ly]], rtol=0, atol=1e-15)
    assert abs(cell["area"] - area) <= 1e-12 * area
    assert abs(xy) > 0.1 * lx
    # contact part of the whole-cell mean stress = LAMMPS' Σ_i S_i / area (its xy is grainlaw's yx)
    m = grainlaw.mean_stress(snap)
    c = m["contact"]
    scale = np.sqrt(sxx**2 + syy**2 + sxy**2) / area
    for ours, lammps in ((c[0, 0], sxx), (c[1, 1], syy), (c[1, 0], sxy)):
        assert abs(ours - lammps / area) <= 1e-6 * scale
    assert c[1, 1] < 0.0
    disks = np.pi * (snap.radii[snap.is_grain] ** 2).sum()
    assert abs(grainlaw.solid_fraction(snap) - disks / area) <= 1e-12
    # a single snapshot: the cell's velocity gradient from the grain velocities
    assert s["velocity_gradient"] == "velocity_profile"


def test_homogenise_a_lammps_shear_series_writes_its_rheology_point(tmp_path):
    d = RVE / "I0.01"
    r = grainlaw.homogenise("lammps", [str(d / "atoms.dump.gz"), str(d / "pairs.dump.gz")], out=tmp_path / "o", mu=0.5)
    s = r["summary"]
    assert "rheology.csv" in r["files"]
    assert s["rve_samples"] == 16 and s["rve_point_verdict"] == "ok"
    assert s["rve_shear_rate_source"] == "cell_deformation"
    assert s["velocity_gradients"] == ["cell_deformation"] * 16
    th = np.loadtxt(d / "thermo.txt", skiprows=1)
    mu_lammps = np.mean(np.abs(th[:, 4]) / th[:, 3])
    assert abs(s["rve_mu"] - mu_lammps) <= s["rve_mu_std_error"]


def test_walls_have_their_own_friction(tmp_path):
    snap = grainlaw.read_snapshots("lammps", lammps_files(), mu=0.5, wall_mu=0.3)[-1]["snapshot"]
    walls = ~snap.is_grain[snap.contact_a]
    assert walls.any() and (~walls).any()
    assert np.all(snap.contact_mu[walls] == 0.3) and np.all(snap.contact_mu[~walls] == 0.5)
    r = grainlaw.homogenise("lammps", lammps_files(), out=tmp_path / "o", mu=0.5, wall_mu=0.3)
    assert "# wall_friction = 3e-1" in (tmp_path / "o" / "janssen.csv").read_text()
