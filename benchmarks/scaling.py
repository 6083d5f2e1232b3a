"""Weak scaling of the MPI runner on this machine: events/s with 1 and 2 ranks, I/O share.

    python benchmarks/scaling.py [--ranks 1 2] [--tasks-per-rank 2] [--events 600] [--transient 200]

Each rank count runs `tasks-per-rank` tasks per rank of the paper setting (N = 800, b = 20,
dt = 1e-3) through `mpiexec -n R python -m ensemble run`, and reports recorded events per
second of the whole run, the weak-scaling efficiency against one rank, and the share of the
busy time spent writing (from the runner's per-rank log lines).
"""
import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CONFIG = """
[model]
N = 800
b = 20.0
[run]
seeds = {seeds}
events = {events}
transient = {transient}
[integrator]
dt = 1e-3
[output]
path = "{path}"
batch = 200
flush_seconds = 10.0
"""


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    p.add_argument("--tasks-per-rank", type=int, default=2)
    p.add_argument("--events", type=int, default=600)
    p.add_argument("--transient", type=int, default=200)
    args = p.parse_args()
    base = None
    with tempfile.TemporaryDirectory() as tmp:
        for ranks in args.ranks:
            path = Path(tmp) / f"n{ranks}.h5"
            cfg = Path(tmp) / f"n{ranks}.toml"
            cfg.write_text(CONFIG.format(seeds=ranks * args.tasks_per_rank, events=args.events,
                                         transient=args.transient, path=path))
            start = time.perf_counter()
            res = subprocess.run(["mpiexec", "-n", str(ranks), sys.executable, "-m", "ensemble", "run",
                                  str(cfg)], capture_output=True, text=True)
            elapsed = time.perf_counter() - start
            if res.returncode != 0:
                sys.exit(f"run with {ranks} ranks failed:\n{res.stderr}")
            busy = io = 0.0
            for m in re.finditer(r"busy ([\d.]+) s \(of which ([\d.]+) s writing", res.stdout):
                busy += float(m.group(1))
                io += float(m.group(2))
            rate = ranks * args.tasks_per_rank * args.events / elapsed
            base = base or rate / ranks
            print(f"{ranks} rank(s): {ranks * args.tasks_per_rank} tasks, {rate:.1f} recorded events/s "
                  f"(wall {elapsed:.1f} s incl. start-up and transient), weak-scaling efficiency "
                  f"{rate / (ranks * base):.2f}, I/O {100 * io / busy:.2f}% of busy time")


if __name__ == "__main__":
    main()
