"""The HDF5 event catalog, one module per job:

    schema.py       what a catalog stores: format, datasets (unit, shape, meaning), codes
    create.py       its layout, made once at creation (collectively under MPI)
    files.py        its name while a run writes it; opening (the file-kind check) and creation
    layout.py       an open catalog's structure; each task's rows read (verified) and written in commit order
    checkpoint.py   a task's state in a checkpoint slot, the commit in use, a task's record for a writer
    writers.py      the parallel (mpio) and the rank-0 writer, one API, and every collective step
    reader.py       Reader, read, read_tasks
    integrity.py    checksums and range checks of the events, checkpoints and commit rows
    histories.py    the event histories (/histories, output.history): written before their commit, read verified
    tables.py       checks of the tables fixed at creation and of each task's record
    errors.py       CatalogError; a failed write as one

No other package touches HDF5 under MPI. Nothing is imported here: callers import the module they use
(`from ensemble.store import reader`).
"""
