"""`analysis reduce` of one catalog by two checkouts, whole processes in alternation, as a ratio.

    python -m benchmarks.reduce_speed CATALOG --before REF [--rounds 5] [--cpu 0] [--out benchmarks/results]

REF is a git revision of this repository: it is checked out (detached) in a temporary worktree and run
with the same interpreter, so the two sides differ only in the analysis code. Each round reduces the
catalog once with REF and once with the working tree (in that order, then the other way in the next
round), each a process of its own (pinned to core `--cpu` with taskset when it exists; `--cpu -1`: not
pinned). A run's cost is its cpu seconds (user + system, from the operating system's accounting of the
finished child), wall seconds beside it; the ratio of this checkout to REF is taken within each round, so
a slow stretch of the machine touches both sides of a pair. The first round of each side loads and
caches its numba kernels and is not counted. Writes reduce_speed.{txt,json}.
"""
import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .common import write_outputs

ROOT = Path(__file__).resolve().parents[1]


def reduce_once(checkout, catalog, out, cpu):
    """(cpu seconds, wall seconds) of one `analysis reduce` by the code of `checkout`."""
    cmd = [sys.executable, "-m", "analysis", "reduce", str(catalog), "-o", str(out), "--force"]
    if cpu >= 0 and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(cpu)] + cmd
    env = {**os.environ, "PYTHONPATH": str(checkout), "OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, check=False, cwd=checkout, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode:
        raise SystemExit(f"benchmarks.reduce_speed: reduce in {checkout} failed (exit {res.returncode}): "
                         f"{(res.stderr or res.stdout).strip().splitlines()[-1:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("catalog")
    p.add_argument("--before", required=True, help="git revision to compare against")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--cpu", type=int, default=0, help="core to pin each process to (-1: none)")
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    catalog = Path(args.catalog).resolve()
    if not catalog.is_file():
        raise SystemExit(f"benchmarks.reduce_speed: no catalog {args.catalog}")
    if args.rounds < 1:
        raise SystemExit("benchmarks.reduce_speed: --rounds must be at least 1")
    rev = subprocess.run(["git", "rev-parse", "--short", args.before], capture_output=True, text=True, cwd=ROOT)
    if rev.returncode:
        raise SystemExit(f"benchmarks.reduce_speed: --before {args.before}: not a revision of {ROOT}")
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "before"
        subprocess.run(["git", "worktree", "add", "-q", "--detach", str(old), args.before], check=True, cwd=ROOT)
        try:
            sides = {"before": old, "now": ROOT}
            cost = {name: [] for name in sides}
            load0 = os.getloadavg()[0]
            for r in range(args.rounds + 1):
                order = list(sides) if r % 2 == 0 else list(sides)[::-1]
                for name in order:
                    cpu, wall = reduce_once(sides[name], catalog, Path(tmp) / f"{name}.h5", args.cpu)
                    if r:
                        cost[name].append((cpu, wall))
                    print(f"round {r}{' (warm-up)' if not r else ''}: {name} {cpu:.2f} cpu s, {wall:.2f} wall s",
                          flush=True)
            load1 = os.getloadavg()[0]
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(old)], check=False, cwd=ROOT)
    ratios = [n[0] / b[0] for n, b in zip(cost["now"], cost["before"])]
    wall_ratios = [n[1] / b[1] for n, b in zip(cost["now"], cost["before"])]
    lines = [f"analysis reduce {catalog.name}: this checkout against {args.before} ({rev.stdout.strip()}), "
             f"{args.rounds} rounds in alternation after one warm-up each (load average {load0:.1f} at the start, "
             f"{load1:.1f} at the end)",
             f"{'side':<8} {'cpu s per round':<40} {'median':>8}"]
    for name in cost:
        lines.append(f"{name:<8} {' '.join(f'{c:.2f}' for c, _ in cost[name]):<40} "
                     f"{statistics.median(c for c, _ in cost[name]):8.2f}")
    lines.append(f"cpu ratio now / before: median {statistics.median(ratios):.3f} "
                 f"({min(ratios):.3f}-{max(ratios):.3f}); wall: {statistics.median(wall_ratios):.3f} "
                 f"({min(wall_ratios):.3f}-{max(wall_ratios):.3f})")
    data = {"catalog": str(catalog), "before": args.before, "revision": rev.stdout.strip(), "rounds": args.rounds,
            "load": [load0, load1], "cost": cost, "cpu_ratios": ratios, "wall_ratios": wall_ratios}
    write_outputs(Path(args.out), "reduce_speed", data, lines)
    return data


if __name__ == "__main__":
    main()
