"""What the Python layer adds: the same work from the command line and from Python, alternating,
several repeats.

    python python/bench/overhead.py [--scenario janssen] [--reps 3] [--set KEY=VALUE ...]
    python python/bench/overhead.py --homogenise-grains 10000 [--reps 5]

The first form compares `grainlaw run SCENARIO ... -q` with `grainlaw.run(...)`; the second
compares `grainlaw homogenise --from lammps ATOMS PAIRS --out DIR --mu 0.5 -q` with
`grainlaw.homogenise("lammps", [ATOMS, PAIRS], out=DIR, mu=0.5)` on the synthetic LAMMPS dump of
`grainlaw bench --homogenise-grains N` (N disks, about 2N contacts; written once into a temporary
directory): reading, homogenising and writing every output (CSV, figures, VTK, summary.json).

The CLI is $GRAINLAW_BIN or the release build in $CARGO_TARGET_DIR (default target/). Both
write the same files into a fresh directory each time; the times are wall-clock, the CLI's
including its process start. CPU seconds (user + system, all threads: the child's for the CLI,
this process's for Python) are printed too: on a shared machine they vary less than wall-clock.
The target is at most 5 % more from Python.
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import grainlaw
from grainlaw import _grainlaw


def cli_binary():
    if os.environ.get("GRAINLAW_BIN"):
        return os.environ["GRAINLAW_BIN"]
    root = Path(__file__).resolve().parents[2]
    return str(Path(os.environ.get("CARGO_TARGET_DIR", root / "target")) / "release" / "grainlaw")


def compare(reps, tmp, cli_args, py_call):
    """Runs `exe *cli_args(out)` and `py_call(out)` alternately `reps` times each; returns the
    wall, inner (summary's wall_seconds) and CPU times of each."""
    times = {"cli": ([], [], []), "py": ([], [], [])}
    for rep in range(reps):
        order = ("cli", "py") if rep % 2 == 0 else ("py", "cli")
        for who in order:
            out = Path(tmp) / f"{who}{rep}"
            wall, inner, cpu = times[who]
            t0 = time.perf_counter()
            if who == "cli":
                c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
                subprocess.run(cli_args(out), check=True)
                wall.append(time.perf_counter() - t0)
                c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu.append(c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime)
                inner.append(json.loads((out / "summary.json").read_text())["wall_seconds"])
            else:
                c0 = time.process_time()
                summary = py_call(out)
                wall.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
                inner.append(summary["wall_seconds"])
    return times


def report(title, reps, times, inner_label):
    print(f"{title}, {reps} repeats, wall-clock seconds")
    print(f"{'':8} {'median':>8} {'min':>8}   {'run alone':>9}   {'CPU med':>8} {'CPU min':>8}")
    for name, key in (("CLI", "cli"), ("Python", "py")):
        t, inner, cpu = times[key]
        print(
            f"{name:8} {statistics.median(t):8.3f} {min(t):8.3f}   {statistics.median(inner):9.3f}"
            f"   {statistics.median(cpu):8.3f} {min(cpu):8.3f}"
        )
    print(f"(run alone: the summary's wall_seconds, {inner_label})")
    for name, key in (("CLI", "cli"), ("Python", "py")):
        t, inner, _ = times[key]
        layer = statistics.median([a - b for a, b in zip(t, inner)])
        print(f"{name}: outside it (process start, arguments, reading, the summary back): {layer:.3f} s")
    (cli_t, _, cli_cpu), (py_t, _, py_cpu) = times["cli"], times["py"]
    over_med = statistics.median(py_t) / statistics.median(cli_t) - 1
    over_min = min(py_t) / min(cli_t) - 1
    over_cpu = min(py_cpu) / min(cli_cpu) - 1
    print(
        f"Python overhead: {100 * over_med:+.1f} % (wall medians), {100 * over_min:+.1f} % (wall minima), "
        f"{100 * over_cpu:+.1f} % (CPU minima); target ≤ 5 %"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="janssen")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument(
        "--homogenise-grains",
        type=int,
        metavar="N",
        help="compare `grainlaw homogenise` on a synthetic LAMMPS dump of N grains instead of a run",
    )
    args = ap.parse_args()
    exe = cli_binary()
    if not Path(exe).exists():
        sys.exit(f"error: no grainlaw executable at {exe} (cargo build --release, or set GRAINLAW_BIN)")
    with tempfile.TemporaryDirectory() as tmp:
        if args.homogenise_grains:
            n = args.homogenise_grains
            atoms, pairs = _grainlaw._synthetic_lammps_dump(n)
            files = [Path(tmp) / f"atoms_{n}.dump", Path(tmp) / f"pairs_{n}.dump"]
            files[0].write_text(atoms)
            files[1].write_text(pairs)
            files = [str(f) for f in files]
            times = compare(
                args.reps,
                tmp,
                lambda out: [exe, "homogenise", "--from", "lammps", "--mu", "0.5", "-q", "--out", str(out), *files],
                lambda out: grainlaw.homogenise("lammps", files, out=out, mu=0.5)["summary"],
            )
            title = f"homogenise --from lammps, synthetic dump of {n} grains and {pairs.splitlines()[3]} contacts"
            report(title, args.reps, times, "homogenisation and outputs, without reading the files")
        else:
            sets = [a for s in args.set for a in ("--set", s)]
            times = compare(
                args.reps,
                tmp,
                lambda out: [exe, "run", args.scenario, "--out", str(out), "-q", *sets],
                lambda out: grainlaw.run(args.scenario, overrides=args.set, out=out)["summary"],
            )
            report(f"scenario {args.scenario} {' '.join(args.set)}", args.reps, times, "the run without process start and read-back")


if __name__ == "__main__":
    main()
