"""Submitting a rendered job: the run job, then the reduction after it (sbatch --dependency=afterok)."""
import shutil
import subprocess


class SubmitError(RuntimeError):
    """sbatch refused a script or is missing."""


def _sbatch(*args):
    if shutil.which("sbatch") is None:
        raise SubmitError("sbatch not found: submit on a login node with bash submit.sh")
    res = subprocess.run(["sbatch", "--parsable", *map(str, args)], capture_output=True, text=True,
                         stdin=subprocess.DEVNULL)
    if res.returncode != 0:
        raise SubmitError(f"sbatch {' '.join(map(str, args))}: {res.stderr.strip() or res.stdout.strip()}")
    return res.stdout.strip().split(";")[0]


def submit(rendered):
    """Submit the run job, then the reduction after it; returns (run job id, reduction job id)."""
    run_id = _sbatch(rendered.run_script)
    reduce_id = _sbatch(f"--dependency=afterok:{run_id}", rendered.reduce_script)
    return run_id, reduce_id
