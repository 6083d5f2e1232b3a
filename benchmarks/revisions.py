"""One command run by the code of a git revision and by this checkout, whole processes in alternation, as a ratio.

    python -m benchmarks.revisions --before REV [--rounds 5] [--cpu 0] [--name NAME] [--out benchmarks/results]
                                   -- COMMAND [ARG ...]

REV is a git revision of this repository: it is checked out (detached) in a temporary worktree, and the
command runs there and here with the same interpreter (`python` as the command's first word is this one),
its working directory and PYTHONPATH the checkout's, so the two sides differ only in the code. `{side}` in
an argument becomes "before" or "now" (an output file of each); give input files as absolute paths. Each
round runs the command once per side (before first, then now first in the next round), each a process of
its own (pinned to core `--cpu` with taskset when it exists; `--cpu -1`: not pinned). A run's cost is its
cpu seconds (user + system, from the operating system's accounting of the finished child), wall seconds
beside it; the ratio now / before is taken within each round, so a slow stretch of the machine touches
both sides of a pair. One round of each side first compiles and caches its numba kernels and is not
counted. Writes revisions_NAME.{txt,json}. Examples (docs/benchmarks.md):

    python -m benchmarks.revisions --before 1f9342c --name reduce_fig1 -- \
        python -m analysis reduce $PWD/runs/fig1/fig1_top_exp4.h5 -o /tmp/{side}.h5 --force
    python -m benchmarks.revisions --before b036696 --name throughput_b20 -- \
        python -m benchmarks.throughput --N 800 --b 20 --method exp4 --events 3000
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


def run_once(checkout, command, side, cpu):
    """(cpu seconds, wall seconds) of one run of `command` by the code of `checkout`."""
    cmd = [sys.executable if (i == 0 and word == "python") else word.replace("{side}", side)
           for i, word in enumerate(command)]
    if cpu >= 0 and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(cpu)] + cmd
    env = {**os.environ, "PYTHONPATH": str(checkout), "OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, check=False, cwd=checkout, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode:
        raise SystemExit(f"benchmarks.revisions: the command failed in {checkout} (exit {res.returncode}): "
                         f"{(res.stderr or res.stdout).strip().splitlines()[-1:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--before", required=True, help="git revision to compare against")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--cpu", type=int, default=0, help="core to pin each process to (-1: none)")
    p.add_argument("--name", default="run", help="the results' name: revisions_NAME.{txt,json}")
    p.add_argument("--out", default="benchmarks/results")
    p.add_argument("command", nargs=argparse.REMAINDER, help="-- COMMAND [ARG ...]")
    args = p.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        raise SystemExit("benchmarks.revisions: no command (give it after --)")
    if args.rounds < 1:
        raise SystemExit("benchmarks.revisions: --rounds must be at least 1")
    rev = subprocess.run(["git", "rev-parse", "--short", args.before], capture_output=True, text=True, cwd=ROOT)
    if rev.returncode:
        raise SystemExit(f"benchmarks.revisions: --before {args.before}: not a revision of {ROOT}")
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
                    cpu, wall = run_once(sides[name], command, name, args.cpu)
                    if r:
                        cost[name].append((cpu, wall))
                    print(f"round {r}{' (warm-up)' if not r else ''}: {name} {cpu:.2f} cpu s, {wall:.2f} wall s",
                          flush=True)
            load1 = os.getloadavg()[0]
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(old)], check=False, cwd=ROOT)
    ratios = [n[0] / b[0] for n, b in zip(cost["now"], cost["before"])]
    wall_ratios = [n[1] / b[1] for n, b in zip(cost["now"], cost["before"])]
    lines = [f"{' '.join(command)}",
             f"this checkout against {args.before} ({rev.stdout.strip()}), {args.rounds} rounds in alternation after "
             f"one warm-up each (load average {load0:.1f} at the start, {load1:.1f} at the end)",
             f"{'side':<8} {'cpu s per round':<40} {'median':>8}"]
    for name in cost:
        lines.append(f"{name:<8} {' '.join(f'{c:.2f}' for c, _ in cost[name]):<40} "
                     f"{statistics.median(c for c, _ in cost[name]):8.2f}")
    lines.append(f"cpu ratio now / before: median {statistics.median(ratios):.3f} "
                 f"({min(ratios):.3f}-{max(ratios):.3f}); wall: {statistics.median(wall_ratios):.3f} "
                 f"({min(wall_ratios):.3f}-{max(wall_ratios):.3f})")
    data = {"command": command, "before": args.before, "revision": rev.stdout.strip(), "rounds": args.rounds,
            "load": [load0, load1], "cost": cost, "cpu_ratios": ratios, "wall_ratios": wall_ratios}
    write_outputs(Path(args.out), f"revisions_{args.name}", data, lines)
    return data


if __name__ == "__main__":
    main()
