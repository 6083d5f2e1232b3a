#!/bin/bash
# A 64 x 64 plane (examples/plane/ranks.toml) run serially, under mpiexec -n 2, and under mpiexec -n 2 killed (-9)
# after 25 s and resumed: the three catalogs' events must be equal, bit for bit. Usage: bash examples/plane/ranks.sh
# [out_dir] (from the repository root; default runs/ranks64). About 3 minutes on two cores.
set -euo pipefail
out=${1:-runs/ranks64}
py=.venv/bin/python
mkdir -p "$out"
rm -f "$out"/{serial,two,killed}.h5 "$out"/killed.h5.partial
$py -m ensemble run examples/plane/ranks.toml -o "$out/serial.h5"
mpiexec -n 2 $py -m ensemble run examples/plane/ranks.toml -o "$out/two.h5"
mpiexec -n 2 $py -m ensemble run examples/plane/ranks.toml -o "$out/killed.h5" > "$out/killed.log" 2>&1 &
sleep 25
pkill -9 -f "$out/killed.h5" || true
wait || true
mpiexec -n 2 $py -m ensemble run examples/plane/ranks.toml -o "$out/killed.h5" --resume
$py - "$out" <<'PY'
import sys
import numpy as np
from ensemble.store import reader
out = sys.argv[1]
serial = reader.read(f"{out}/serial.h5")[0]
for name in ("two", "killed"):
    other = reader.read(f"{out}/{name}.h5")[0]
    same = all(np.array_equal(serial[k], other[k], equal_nan=serial[k].dtype.kind == "f") for k in serial)
    print(f"{name}: {len(other['t'])} rows, identical to the serial catalog: {same}")
    assert same
PY
