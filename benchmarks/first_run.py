"""The first run of every friction law, method and regime on a set-up checkout: what it spends compiling.

    python -m benchmarks.first_run [--N 30] [--events 20] [--in-process] [--out benchmarks/results]

For every law of the registry, every method that law takes (model/methods.py, Method.refusal) and every
regime it has (a chain above its blocks' stiffness; for a law that creeps, also a creeping chain, b = 15
and a = 3 below the stiffness 1 + 2 l^2 = 19), runs `python -m ensemble run` on a tiny config (N blocks,
`events` events, one seed), each a process of its own (`--in-process`: all in this one, after each other),
and counts numba's compilations in it (its "numba:compile" events: only a real compilation sends one, a
kernel loaded from the cache does not) and the seconds they took. After `make setup` (which runs
`python -m ensemble compile`) every count is 0; on a cold cache the first run of each law compiles for
about a minute. Writes first_run.{txt,json}.
"""
import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .common import write_outputs

ROOT = Path(__file__).resolve().parents[1]
# a creeping chain: b below the chain's block stiffness 1 + 2 l^2 = 19 at l = 3 (docs/numerics.md)
CREEPING = {"b": 15.0, "a": 3.0}


def cases():
    """(law, method, regime, [model] keys) of every first run to measure."""
    from ensemble.model import laws
    from ensemble.model.methods import METHODS
    out = []
    for name, law in sorted(laws.LAWS.items()):
        regimes = [("events", {})] + ([("creep", CREEPING)] if law.creeps else [])
        for method in METHODS:
            if METHODS[method].refusal(law) is None:
                out.extend((name, method, regime, keys) for regime, keys in regimes)
    return out


def config_text(law, method, keys, N, events, out):
    model = "".join(f"{k} = {v!r}\n" for k, v in {"N": N, "law": law, **keys}.items()).replace("'", '"')
    return (f"[model]\n{model}[run]\nevents = {events}\ntransient = 0\nseeds = 1\n"
            f"[integrator]\nmethod = \"{method}\"\n[output]\npath = \"{out}\"\n")


def run_counting(config):
    """`python -m ensemble run CONFIG --force` in this process: (exit code, compilations, seconds compiling,
    seconds in all)."""
    from numba.core import event as numba_event

    from ensemble.cli import main
    starts, counted = [], {"n": 0, "seconds": 0.0}

    class Listener(numba_event.Listener):
        def on_start(self, event):
            starts.append(time.perf_counter())

        def on_end(self, event):
            seconds = time.perf_counter() - starts.pop()
            counted["n"] += 1
            if not starts:          # the outermost compilation's time holds the nested ones'
                counted["seconds"] += seconds

    listener = Listener()
    numba_event.register("numba:compile", listener)
    start = time.perf_counter()
    try:
        code = main(["run", str(config), "--force"])
    finally:
        numba_event.unregister("numba:compile", listener)
    return code, counted["n"], counted["seconds"], time.perf_counter() - start


def measure(N=30, events=20, in_process=False, work=None):
    """One row per case: law, method, regime, exit code, compilations, seconds compiling, seconds in all."""
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        work = Path(work or scratch)
        for k, (law, method, regime, keys) in enumerate(cases()):
            config = work / f"case{k}.toml"
            config.write_text(config_text(law, method, keys, N, events, work / f"case{k}.h5"))
            if in_process:
                code, n, seconds, total = run_counting(config)
            else:
                res = subprocess.run([sys.executable, "-m", "benchmarks.first_run", "--one", str(config)],
                                     capture_output=True, text=True, cwd=ROOT, check=False)
                if res.returncode:
                    raise SystemExit(f"benchmarks.first_run: {law} {method} {regime} failed:\n"
                                     f"{res.stdout}{res.stderr}")
                code, n, seconds, total = json.loads(res.stdout.strip().splitlines()[-1])
            rows.append({"law": law, "method": method, "regime": regime, "exit": code, "compilations": n,
                         "compiling_seconds": seconds, "seconds": total})
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=30)
    p.add_argument("--events", type=int, default=20)
    p.add_argument("--in-process", action="store_true", help="every run in this process")
    p.add_argument("--one", metavar="CONFIG", help=argparse.SUPPRESS)     # a child: one run, its numbers as JSON
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    if args.one:
        import contextlib
        import io
        with contextlib.redirect_stdout(io.StringIO()):
            numbers = run_counting(args.one)
        print(json.dumps(numbers))
        return 0
    start = time.perf_counter()
    rows = measure(args.N, args.events, args.in_process)
    mode = "all in one process" if args.in_process else "each a process of its own"
    lines = [f"first runs (N = {args.N}, {args.events} events, {mode}): numba compilations and their seconds",
             f"{'law':<15} {'method':<6} {'regime':<7} {'compilations':>12} {'compiling s':>12} {'run s':>7}"]
    lines += [f"{r['law']:<15} {r['method']:<6} {r['regime']:<7} {r['compilations']:>12} "
              f"{r['compiling_seconds']:>12.1f} {r['seconds']:>7.1f}" for r in rows]
    lines.append(f"largest time compiling: {max(r['compiling_seconds'] for r in rows):.1f} s "
                 f"({time.perf_counter() - start:.0f} s in all)")
    write_outputs(Path(args.out), "first_run", {"N": args.N, "events": args.events, "mode": mode, "rows": rows},
                  lines)
    return 0


if __name__ == "__main__":
    sys.exit(main())
