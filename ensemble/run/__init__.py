"""A run: config -> tasks -> kernel calls on every rank -> one catalog, one module per job:

    context.py      RunContext: the config, ranks, paths, options and (once open) writer, counter, progress
    tasks.py        each task's own random stream and initial state (which tasks: ensemble/sweep.py)
    branching.py    run.branch: the spin-ups a run needs, and the state a branch starts from
    decision.py     rank 0's decision about the files before any work: new, resume, complete, refused
    runner.py       run(ctx): the lock, the decision, the catalog opened, the work served, closed and renamed
    worker.py       one rank's work: items from the shared counter; a task or a spin-up in kernel calls, commits
    trajectory.py   one task's chain between events: the wrapper from config to kernel, the event rows
    progress.py     rank 0's progress line, in the log and in the lock file
    parallel.py     the MPI plumbing: the shared task counter, event counts, stop requests (signals)
    lock.py         one run per catalog: the lock file beside it, its heartbeat, stale locks
    abort.py        one rank's exception ends every rank (for the entry points, here and in analysis)
    status.py       `python -m ensemble status`: what a catalog holds and what its run is doing

The catalog itself is ensemble/store/, the kernels ensemble/model/; the command line (cli.py) makes the
RunContext and calls runner.run. Shared with other commands and left beside the package: space.py (the
disk check, also the store's), environment.py (the software stack, also validate's and the Slurm
jobs'), sweep.py (the task list, also the store's, the Slurm jobs' and the regional reduction's), checks.py
and filekind.py. Nothing is imported here: callers import the module they use
(`from ensemble.run import runner`).
"""
