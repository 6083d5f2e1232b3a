#!/bin/bash
# The plane's runs and study behind docs/plane.md. Usage: bash examples/plane/run.sh [out_dir] (from the repository
# root; out_dir defaults to runs/plane; a catalog already there is kept). About two hours on two cores: the 64 x 64
# plane's 1e5 events are two seeds of 5e4 (p64.toml with run.seed 0 and 1), run side by side.
set -euo pipefail
out=${1:-runs/plane}
py=.venv/bin/python
mkdir -p "$out" docs/plane
pids=()
for seed in 0 1; do
    if [ ! -e "$out/p64_s$seed.h5" ]; then
        $py -m ensemble run examples/plane/p64.toml --set run.events=50000 --set run.seed=$seed \
            -o "$out/p64_s$seed.h5" &
        pids+=($!)
    fi
done
for name in p32 chain p32_b20; do
    [ -e "$out/$name.h5" ] || $py -m ensemble run "examples/plane/$name.toml" -o "$out/$name.h5"
done
for pid in "${pids[@]}"; do wait "$pid"; done      # a failed seed stops the script here
$py -m examples.plane.study "$out/p32.h5" "$out/p64_s0.h5" "$out/p64_s1.h5" "$out/chain.h5" "$out/p32_b20.h5" \
    --histories "$out/p64_s0.h5" "$out/p64_s1.h5" -o docs/plane/study
$py -m benchmarks.cost_scaling --plane --runs exp4 --Ns 32 64 128 --bs --b-at 40 --events 2000 --budget 300 \
    --transient-per-block 0 --min-transient 300 --out benchmarks/results --name plane_cost
$py -m benchmarks.cost_scaling --plane --runs exp4 --Ns 256 --bs --b-at 40 --events 2000 --budget 300 \
    --transient-per-block 0 --min-transient 300 --out benchmarks/results --name plane_cost_256
