# Sourced by the scripts beside it: run_or_resume CONFIG CATALOG RANKS [--set KEY=VALUE ...] runs CONFIG (with the
# overrides) into CATALOG under mpirun, resumes it if interrupted (its .partial is there: the catalog keeps its
# config), and does nothing if it is finished.
run_or_resume() {
    local config=$1 catalog=$2 ranks=$3
    shift 3
    if [ -e "$catalog.partial" ]; then
        mpirun -n "$ranks" .venv/bin/python -m ensemble resume "$catalog"
    elif [ ! -e "$catalog" ]; then
        mpirun -n "$ranks" .venv/bin/python -m ensemble run "$config" -o "$catalog" "$@"
    fi
}
