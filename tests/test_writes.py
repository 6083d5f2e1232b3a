"""Every file the commands write, walked: each is written by the one helper (ensemble/space.py `write_file`: never
through a symbolic link, its blocks reserved first where the size is known), or is a run's catalog (the HDF5 file
written in place, its blocks reserved by store/files.py, its names refused as links by checks.output) or its lock
(run/lock.py, opened O_NOFOLLOW).

The commands run in this process with `space.write_file` wrapped to record what it wrote; a file any command
leaves that the wrapper did not see was written around the helper, and the test names it. A second test reads the
package's source for the calls that write files, so that a writer no command here reaches is found too."""
import ast
from pathlib import Path

import pytest

from analysis import cli as analysis_cli
from ensemble import cli as ensemble_cli
from ensemble import space

from .conftest import write_config
from .processes import ROOT


@pytest.fixture
def written(monkeypatch):
    """The paths space.write_file wrote in this test, resolved."""
    seen = set()
    real = space.write_file

    def recording(path, data, what):
        real(path, data, what)
        seen.add(Path(path).resolve())
    monkeypatch.setattr(space, "write_file", recording)
    return seen


def files_under(folder):
    return {p.resolve() for p in Path(folder).rglob("*") if p.is_file()}


def test_every_file_a_command_writes_goes_through_the_helper(tmp_path, written):
    cfg = write_config(tmp_path / "w.toml", model={"N": 20}, run={"events": 60, "transient": 10, "seeds": 2})
    catalog, other = tmp_path / "w.h5", tmp_path / "other.h5"
    before = files_under(tmp_path)
    assert ensemble_cli.main(["run", str(cfg), "-o", str(catalog)]) == 0
    assert ensemble_cli.main(["run", str(cfg), "-o", str(other), "--set", "run.seed=9"]) == 0
    summary = tmp_path / "w.summary.h5"
    steps = [
        (ensemble_cli, ["slurm", str(cfg), "--ntasks", "2", "--time", "10", "-o", str(tmp_path / "job")]),
        (ensemble_cli, ["slurm", str(cfg), "--ntasks", "2", "--time", "10", "--kind", "array", "-o",
                        str(tmp_path / "array")]),
        (analysis_cli, ["reduce", str(catalog), "-o", str(summary), "--bootstrap", "10"]),
        (analysis_cli, ["plot", str(summary), "--figure", "magnitude", "-o", str(tmp_path / "m.png")]),
        (analysis_cli, ["plot", str(summary), "--figure", "recurrence", "-o", str(tmp_path / "r.pdf")]),
        (analysis_cli, ["export", str(catalog), "-o", str(tmp_path / "catalog-tables")]),
        (analysis_cli, ["export", str(summary), "-o", str(tmp_path / "summary-tables")]),
        (analysis_cli, ["compare", str(catalog), str(other), "-o", str(tmp_path / "comparison"),
                        "--bootstrap", "10", "--n-large", "5"]),
    ]
    for module, argv in steps:
        assert module.main(argv) == 0, argv
    made = files_under(tmp_path) - before
    catalogs = {catalog.resolve(), other.resolve()}
    # a summary or a table is written as NAME.partial and renamed when whole
    helped = written | {p.with_name(p.name.removesuffix(".partial")) for p in written}
    assert catalogs <= made and summary.resolve() in helped
    kinds = {p.suffix for p in helped}
    assert {".sh", ".sbatch", ".toml", ".h5", ".png", ".pdf", ".csv", ".md", ".json"} <= kinds, kinds
    bypassed = sorted(str(p.relative_to(tmp_path)) for p in made - helped - catalogs)
    assert not bypassed, f"written around ensemble/space.py write_file: {bypassed}"


# the calls that write a file, and the modules allowed to make them: the helper itself, the catalog's HDF5 writer,
# the lock, the reservation of a catalog's blocks, and stdout sent to /dev/null
WRITERS = {"savefig", "write_text", "write_bytes", "dump", "to_csv", "tofile", "save", "savez", "File", "open"}
ALLOWED = {
    "ensemble/space.py": {"open"},              # write_file, and the scratch file of check_fits
    "ensemble/store/writers.py": {"File"},       # the catalog, HDF5 in place (reserved by store/files.py)
    "ensemble/store/files.py": {"open", "File"},  # reserve_space: the catalog's own blocks; opening it
    "ensemble/run/lock.py": {"open"},           # the lock, O_NOFOLLOW
    "ensemble/cli.py": {"open"},                # /dev/null as stdout
    "ensemble/pipes.py": {"open"},              # the same
    "ensemble/checks.py": {"write_text"},       # the text front of write_file
    "analysis/drawing.py": {"savefig", "save"},  # into memory, then write_file
    "analysis/summary.py": {"File"},            # into memory (BytesIO), then write_file
}
READ_MODES = {"r", "rb", "rt"}


def _writes(call):
    """The name of the write a call makes, or None (reads: open and h5py.File in a read mode, os.open read-only)."""
    fn = call.func
    name = fn.attr if isinstance(fn, ast.Attribute) else fn.id if isinstance(fn, ast.Name) else None
    if name not in WRITERS or isinstance(fn, ast.Name) and name == "save":     # drawing.save: the helper's front
        return None
    if isinstance(fn, ast.Attribute) and getattr(fn.value, "id", "") in ("checks", "space"):   # the helper's fronts
        return None
    if name in ("open", "File"):
        mode = call.args[1] if len(call.args) > 1 else next((k.value for k in call.keywords if k.arg == "mode"), None)
        if isinstance(fn, ast.Attribute) and fn.attr == "open" and getattr(fn.value, "id", "") == "os":
            flags = ast.unparse(call.args[1]) if len(call.args) > 1 else ""
            return name if any(f in flags for f in ("O_WRONLY", "O_RDWR", "O_CREAT")) else None
        if mode is None or (isinstance(mode, ast.Constant) and mode.value in READ_MODES):
            return None
    return name


def test_no_module_writes_a_file_around_the_helper():
    found = []
    for package in ("ensemble", "analysis"):
        for path in sorted((ROOT / package).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            for node in ast.walk(ast.parse(path.read_text(), rel)):
                if isinstance(node, ast.Call) and (name := _writes(node)) and name not in ALLOWED.get(rel, ()):
                    found.append(f"{rel}:{node.lineno} {ast.unparse(node)[:80]}")
    assert not found, "files written around ensemble/space.py write_file:\n" + "\n".join(found)
