"""Events per second of several kernel settings, whole processes in alternation, as ratios to the first.

    python -m benchmarks.paired [--N 800] [--b 20] [--rounds 3] [--transient 1000] [--events 1000]
                                [--runs rk4:dt=1e-3 ark4:rtol=1e-4 exp4:rtol=1e-4 exp4:rtol=1e-3]
                                [--cpu 0] [--out benchmarks/results]

Each round runs `benchmarks/throughput.py` once per setting, in the order given, each a process of its
own (pinned to core `--cpu` with taskset when it exists; `--cpu -1`: not pinned), from the same
initial state (seed 0). A run's rate is its recorded events per cpu-second of its timed stretch (the
transient, which includes loading the cached kernels, is not timed). The ratio of a setting to the
first is taken within each round, so a slow stretch of the machine touches both sides of a pair; the
table gives each round's rates, the median rate and the median (min-max) of the per-round ratios.
The load average at the start and end is printed beside it: ratios are what holds on a shared
machine, rates only on a quiet one. Writes paired_N{N}_b{b}.{txt,json}.
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

from .common import parse_setting, write_outputs

ROOT = Path(__file__).resolve().parents[1]
RATE = re.compile(r"([0-9.]+) events per cpu-second")


def command(setting, args):
    kw = setting.kwargs
    cmd = [sys.executable, "-m", "benchmarks.throughput", "--N", str(args.N), "--b", str(args.b),
           "--method", setting.name, "--transient", str(args.transient), "--events", str(args.events)]
    for key in ("dt", "rtol"):
        if key in kw:
            cmd += [f"--{key}", repr(kw[key])]
    unknown = set(kw) - {"dt", "rtol"}
    if unknown:
        raise ValueError(f"setting {setting.label!r}: throughput takes dt and rtol only, "
                         f"not {', '.join(sorted(unknown))}")
    if args.cpu >= 0 and shutil.which("taskset"):
        cmd = ["taskset", "-c", str(args.cpu)] + cmd
    return cmd


def run_once(setting, args):
    out = subprocess.run(command(setting, args), capture_output=True, text=True, check=False, cwd=ROOT)
    found = RATE.search(out.stdout)
    if out.returncode or not found:
        raise SystemExit(f"benchmarks.paired: {setting.label} failed (exit {out.returncode}): "
                         f"{(out.stderr or out.stdout).strip().splitlines()[-1:]}")
    return float(found.group(1))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=800)
    p.add_argument("--b", type=float, default=20.0)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--transient", type=int, default=1000)
    p.add_argument("--events", type=int, default=1000)
    p.add_argument("--runs", nargs="+", default=["rk4:dt=1e-3", "ark4:rtol=1e-4", "exp4:rtol=1e-4", "exp4:rtol=1e-3"],
                   help="settings; the first is the baseline of the ratios")
    p.add_argument("--cpu", type=int, default=0, help="core to pin each process to (-1: none)")
    p.add_argument("--out", default="benchmarks/results")
    args = p.parse_args(argv)
    try:
        settings = [parse_setting(text) for text in args.runs]
        for s in settings:
            command(s, args)
    except ValueError as err:
        raise SystemExit(f"benchmarks.paired: {err}") from None
    load0 = os.getloadavg()[0]
    rates = {s.label: [] for s in settings}
    for r in range(args.rounds):
        for s in settings:
            rates[s.label].append(run_once(s, args))
            print(f"round {r + 1}: {s.label} {rates[s.label][-1]:.1f} events per cpu-second", flush=True)
    load1 = os.getloadavg()[0]
    base = settings[0].label
    lines = [f"events per cpu-second, N = {args.N}, b = {args.b:g}, {args.transient} transient + {args.events} "
             f"timed events per run, {args.rounds} rounds in alternation (load average {load0:.1f} at the start, "
             f"{load1:.1f} at the end)",
             f"{'setting':<18} {'rounds':<28} {'median':>8}  ratio to {base}, median (min-max)"]
    data = {"N": args.N, "b": args.b, "rounds": args.rounds, "transient": args.transient, "events": args.events,
            "load": [load0, load1], "baseline": base, "settings": {}}
    for s in settings:
        ratios = [x / y for x, y in zip(rates[s.label], rates[base])]
        lines.append(f"{s.label:<18} {' '.join(f'{x:.0f}' for x in rates[s.label]):<28} "
                     f"{statistics.median(rates[s.label]):8.1f}  {statistics.median(ratios):.2f} "
                     f"({min(ratios):.2f}-{max(ratios):.2f})")
        data["settings"][s.label] = {"rates": rates[s.label], "ratios": ratios}
    print("\n".join(lines))
    write_outputs(Path(args.out), f"paired_N{args.N}_b{args.b:g}", data, lines)
    return data


if __name__ == "__main__":
    main()
