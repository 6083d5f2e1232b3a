#!/bin/bash
# The plane's runs and study behind docs/plane.md. Usage: bash examples/plane/run.sh [out_dir] (from the repository
# root; out_dir defaults to runs/plane; a catalog already there is kept). About an hour on one core in all.
set -euo pipefail
out=${1:-runs/plane}
py=.venv/bin/python
mkdir -p "$out" docs/plane
for name in p32 p64 chain p32_b20; do
    [ -e "$out/$name.h5" ] || $py -m ensemble run "examples/plane/$name.toml" -o "$out/$name.h5"
done
$py -m examples.plane.study "$out/p32.h5" "$out/p64.h5" "$out/chain.h5" "$out/p32_b20.h5" --histories "$out/p64.h5" \
    -o docs/plane/study
$py -m benchmarks.cost_scaling --plane --runs exp4 --Ns 32 64 128 --bs --b-at 40 --events 2000 --budget 300 \
    --transient-per-block 0 --min-transient 300 --out benchmarks/results --name plane_cost
$py -m benchmarks.cost_scaling --plane --runs exp4 --Ns 256 --bs --b-at 40 --events 2000 --budget 300 \
    --transient-per-block 0 --min-transient 300 --out benchmarks/results --name plane_cost_256
