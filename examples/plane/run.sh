#!/bin/bash
# The plane's runs and study behind docs/plane.md. Usage: bash examples/plane/run.sh [out_dir] (from the repository
# root; out_dir defaults to runs/plane; a catalog already there is kept, a partial one resumed). About five hours on
# two cores: the 64 x 64 plane's 1e5 events are two seeds of 5e4 (p64.toml with run.seed 0 and 1), run side by side;
# the 128 x 128 and 256 x 256 planes' are two tasks of one run under `mpiexec -n 2`.
set -euo pipefail
out=${1:-runs/plane}
py=.venv/bin/python
mkdir -p "$out" docs/plane

run() {     # run [LAUNCHER...] -- CONFIG OUT [ARGS...]: a finished catalog kept, a partial one resumed
    local launch=()
    while [ "$1" != "--" ]; do launch+=("$1"); shift; done
    local cfg=$2 dest=$3
    shift 3
    if [ -e "$dest.partial" ]; then
        "${launch[@]}" $py -m ensemble resume "$dest.partial"
    elif [ ! -e "$dest" ]; then
        "${launch[@]}" $py -m ensemble run "$cfg" -o "$dest" "$@"
    fi
}

pids=()
for seed in 0 1; do
    run -- examples/plane/p64.toml "$out/p64_s$seed.h5" --set run.events=50000 --set run.seed=$seed &
    pids+=($!)
done
for name in p32 chain p32_b20; do
    run -- "examples/plane/$name.toml" "$out/$name.h5"
done
for pid in "${pids[@]}"; do wait "$pid"; done      # a failed seed stops the script here
for side in 128 256; do
    run mpiexec -n 2 -- "examples/plane/p$side.toml" "$out/p$side.h5"
done
$py -m examples.plane.study "$out/p32.h5" "$out/p64_s0.h5" "$out/p64_s1.h5" "$out/p128.h5" "$out/p256.h5" \
    "$out/chain.h5" "$out/p32_b20.h5" --histories "$out/p64_s0.h5" "$out/p64_s1.h5" "$out/p256.h5" \
    -o docs/plane/study
$py -m benchmarks.cost_scaling --plane --runs exp4 --Ns 32 64 128 --bs --b-at 40 --events 2000 --budget 300 \
    --transient-per-block 0 --min-transient 300 --out benchmarks/results --name plane_cost
$py -m benchmarks.cost_scaling --plane --runs exp4 --Ns 256 --bs --b-at 40 --events 2000 --budget 300 \
    --transient-per-block 0 --min-transient 300 --out benchmarks/results --name plane_cost_256
