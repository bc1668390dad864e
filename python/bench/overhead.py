"""What the Python layer adds to a scenario run: `grainlaw.run(...)` against the command line
`grainlaw run ... -q` on the same scenario, same overrides, alternating, several repeats.

    python python/bench/overhead.py [--scenario janssen] [--reps 3] [--set KEY=VALUE ...]

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


def cli_binary():
    if os.environ.get("GRAINLAW_BIN"):
        return os.environ["GRAINLAW_BIN"]
    root = Path(__file__).resolve().parents[2]
    return str(Path(os.environ.get("CARGO_TARGET_DIR", root / "target")) / "release" / "grainlaw")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="janssen")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args()
    exe = cli_binary()
    if not Path(exe).exists():
        sys.exit(f"error: no grainlaw executable at {exe} (cargo build --release, or set GRAINLAW_BIN)")
    sets = [a for s in args.set for a in ("--set", s)]
    cli_t, py_t, cli_in, py_in, cli_cpu, py_cpu = [], [], [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(args.reps):
            order = ("cli", "py") if rep % 2 == 0 else ("py", "cli")
            for who in order:
                out = Path(tmp) / f"{who}{rep}"
                t0 = time.perf_counter()
                if who == "cli":
                    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
                    subprocess.run([exe, "run", args.scenario, "--out", str(out), "-q", *sets], check=True)
                    cli_t.append(time.perf_counter() - t0)
                    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
                    cli_cpu.append(c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime)
                    cli_in.append(json.loads((out / "summary.json").read_text())["wall_seconds"])
                else:
                    c0 = time.process_time()
                    r = grainlaw.run(args.scenario, overrides=args.set, out=out)
                    py_t.append(time.perf_counter() - t0)
                    py_cpu.append(time.process_time() - c0)
                    py_in.append(r["summary"]["wall_seconds"])
    print(f"scenario {args.scenario} {' '.join(args.set)}, {args.reps} repeats, wall-clock seconds")
    print(f"{'':8} {'median':>8} {'min':>8}   {'run alone':>9}   {'CPU med':>8} {'CPU min':>8}")
    for name, t, inner, cpu in (("CLI", cli_t, cli_in, cli_cpu), ("Python", py_t, py_in, py_cpu)):
        print(
            f"{name:8} {statistics.median(t):8.3f} {min(t):8.3f}   {statistics.median(inner):9.3f}"
            f"   {statistics.median(cpu):8.3f} {min(cpu):8.3f}"
        )
    print("(run alone: the summary's wall_seconds, the run without process start and read-back)")
    for name, t, inner in (("CLI", cli_t, cli_in), ("Python", py_t, py_in)):
        layer = statistics.median([a - b for a, b in zip(t, inner)])
        print(f"{name}: outside the run (process start, arguments, reading the files back): {layer:.3f} s")
    over_med = statistics.median(py_t) / statistics.median(cli_t) - 1
    over_min = min(py_t) / min(cli_t) - 1
    over_cpu = min(py_cpu) / min(cli_cpu) - 1
    print(
        f"Python overhead: {100 * over_med:+.1f} % (wall medians), {100 * over_min:+.1f} % (wall minima), "
        f"{100 * over_cpu:+.1f} % (CPU minima); target ≤ 5 %"
    )


if __name__ == "__main__":
    main()
