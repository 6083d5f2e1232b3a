"""`python -m ensemble slurm`: fill the job templates of jobs/ from a config, and submit them; one module per job:

    options.py      JobOptions (every option of a job, with its default), their checks, Slurm time limits
    kinds.py        the kinds of run job (KINDS) and what each writes besides its scripts: configs, catalogs
    render.py       the placeholders, filling a template, and render(): a job directory written whole
    stack.py        the MPI and the package the jobs' python has (started outside the repository)
    submit.py       sbatch: the run job, then the reduction after it
    command.py      the command's options and its report of what was written

The templates are plain sbatch scripts with @NAME@ placeholders (listed in render.PLACEHOLDERS and
in jobs/README.md). Filling one replaces each placeholder by its value; a line holding a
placeholder whose value is empty (no partition, no account, ...) is dropped. Everything a job
needs goes into one directory: the scripts, a snapshot of the resolved config (so that editing
the original later does not change a queued run), the catalog(s), logs/ and results/.

Kinds of run job (kinds.KINDS): "single" (one MPI run), "requeue" (walltime-safe: checkpoint before
the limit, requeue, resume), "array" (one walltime-safe element per parameter point). Each comes
with reduce.sbatch, submitted with --dependency=afterok on the run job, which reduces the run's
catalog (an array's per-point catalogs together) into one summary, its figures and report; it has
a time limit, partition and memory of its own (a reduction is short and needs one rank).

A job directory that exists is not written over without force (its config snapshot is what a
queued run reads). mpi4py and h5py are built against one MPI, which the nodes must have too: the
scripts and the command's output name it (stack.python_stack()).

A package beside ensemble/run/, not inside it: it starts no run (the jobs do, through
`python -m ensemble run|resume`) and imports nothing of the run (the task list is ensemble/sweep.py).
Nothing is imported here: callers import the module they use (`from ensemble.slurm import render`).
"""
