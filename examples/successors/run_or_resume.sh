# Sourced by the scripts beside it: run_or_resume CONFIG CATALOG RANKS runs CONFIG into CATALOG under mpirun, resumes
# it if interrupted (its .partial is there), and does nothing if it is finished.
run_or_resume() {
    if [ -e "$2.partial" ]; then
        mpirun -n "$3" .venv/bin/python -m ensemble resume "$2"
    elif [ ! -e "$2" ]; then
        mpirun -n "$3" .venv/bin/python -m ensemble run "$1" -o "$2"
    fi
}
