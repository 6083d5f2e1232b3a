"""One rank's exception ends every rank, at once: no job left hanging in MPI.

Under mpirun every rank runs the same command. If one rank raises while the others wait for
it in a collective call (gather, bcast, a barrier, a collective HDF5 close), they wait forever;
MPI_Abort makes the process manager kill them all. Errors that every rank raises alike - a bad
config, a missing file, decided on rank 0 and broadcast (`on_root`) - need no abort: rank 0
prints them once and every rank returns the same exit code.

    return run_guarded(comm, body, {ConfigError: 2, CatalogError: 1})

Library code only raises (STYLE.md 6); these are for entry points.
"""
import sys
import time
from contextlib import contextmanager

# MPI_Abort makes the process manager kill every rank, and what a rank wrote to its stderr pipe
# but the manager has not yet forwarded is lost (seen with MPICH's Hydra): give it a moment.
ABORT_GRACE_SECONDS = 1.0


def abort(comm, err):
    """Print "error: rank R: ERR"; with other ranks, abort them all (then it does not return)."""
    print(f"error: rank {comm.Get_rank()}: {str(err) or type(err).__name__}", file=sys.stderr, flush=True)
    if comm.Get_size() > 1:
        time.sleep(ABORT_GRACE_SECONDS)
        comm.Abort(1)


@contextmanager
def abort_on_error(comm):
    """Any exception inside is this rank's alone (others may be waiting for it): abort all ranks.

    Alone (one rank) nobody waits, so the exception propagates to the caller unchanged.
    """
    try:
        yield
    except Exception as err:   # raised again: one rank alone aborts nobody
        if comm.Get_size() > 1:
            abort(comm, err)
        raise


def run_guarded(comm, body, codes):
    """body() -> exit code, on every rank; exceptions become messages and exit codes.

    codes: {exception class: exit code} of errors every rank raises alike (rank 0 prints
    "error: MSG" once; every rank returns the code). Any other exception: that rank prints
    "error: rank R: MSG" and aborts all ranks (MPI_Abort(1)); alone, it returns 1.
    """
    try:
        return body()
    except BrokenPipeError as err:
        if comm.Get_size() > 1:
            abort(comm, err)
        raise   # alone: stdout's reader went away, not a failure; __main__ ends quietly
    except tuple(codes) as err:
        if comm.Get_rank() == 0:
            print(f"error: {err}", file=sys.stderr, flush=True)
        return next(code for cls, code in codes.items() if isinstance(err, cls))
    except Exception as err:  # noqa: BLE001 - the guard that turns any failure into an abort
        abort(comm, err)
        return 1


def on_root(comm, fn, errors):
    """fn() on rank 0 only, its result on every rank; an exception of a class in `errors` is
    raised on every rank alike (so run_guarded's codes hold), any other aborts all ranks.

    Rank 0 decides (reads a file, checks an option) and the others follow: were each rank to
    look for itself, one could see a file that another does not and leave it waiting.
    """
    outcome = None
    if comm.Get_rank() == 0:
        with abort_on_error(comm):
            try:
                outcome = (True, fn())
            except errors as err:
                outcome = (False, err)
    ok, value = comm.bcast(outcome, root=0)
    if not ok:
        raise value
    return value
