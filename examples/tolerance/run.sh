#!/usr/bin/env bash
# One catalog per integrator setting of examples/tolerance/base.toml, the tight reference first:
#   bash examples/tolerance/run.sh [RANKS [NAME ...]]   (default 1 rank, every setting; a few core-hours in all)
# A complete catalog is skipped and an interrupted one resumed, so the script can be stopped and
# started again at any time. The candidates run the config's root seed (the same initial states);
# the reference runs another (run.seed + 1), so that a candidate and the reference are independent
# samples, as benchmarks/statistics.py has them. reference-seed7 is the reference's integrator from the
# candidates' seed (benchmarks/statistics.py --rerun: its distance from the reference joins the noise floor).
# NAMEs select settings, e.g. `bash examples/tolerance/run.sh 2 reference exp4-1e-4 exp4-1e-3`.
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS=${1:-1}
. examples/run_or_resume.sh
SETTINGS="reference:ark4:1e-7 ark4-1e-3:ark4:1e-3 ark4-1e-4:ark4:1e-4 ark4-1e-5:ark4:1e-5 ark4-1e-6:ark4:1e-6
          rk4-1e-3:rk4:1e-3 exp4-1e-4:exp4:1e-4 exp4-1e-3:exp4:1e-3 reference-seed7:ark4:1e-7"
shift || true
for name in "$@"; do
  case " $SETTINGS" in *" $name:"*) ;; *) echo "examples/tolerance/run.sh: no setting named $name" >&2; exit 2;; esac
done
for s in $SETTINGS; do
  IFS=: read -r name method value <<< "$s"
  if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
  if [ "$method" = rk4 ]; then set_value="integrator.dt=$value"; else set_value="integrator.rtol=$value"; fi
  if [ "$name" = reference ]; then seed="run.seed=8"; else seed="run.seed=7"; fi
  run_or_resume "runs/tolerance/$name.h5" examples/tolerance/base.toml \
    --set "integrator.method=\"$method\"" --set "$set_value" --set "$seed"
done
