"""Wrong input ends in one line naming the file or key, never a traceback or a hang.

Config files that are not configs, non-finite and overflowing parameters, files of the wrong
kind or damaged given to analysis, one failing rank under mpiexec, and a closed stdout pipe.
"""
import math
import os
import shutil
import sys
from dataclasses import fields

import h5py
import pytest

from analysis import summary
from ensemble import filekind
from ensemble.store import reader
from ensemble.store.errors import CatalogError
from ensemble.config import SECTIONS, ConfigError, load, loads

from .conftest import write_config
from .processes import Started, analysis_here, child_env, ensemble_here, run_bounded

TIMEOUT = 120   # seconds for any one command; what these run takes a few


def run(package, *args, timeout=TIMEOUT, **kwargs):
    return run_bounded([sys.executable, "-m", package, *args], timeout, env=child_env(), **kwargs)


def one_error_line(res, code):
    """The single stderr line of a failed command with exit code `code`."""
    assert res.returncode == code, (res.returncode, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), res.stderr
    return lines[0]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A small catalog (2 tasks), its summary, a config, and things that are none of these."""
    d = tmp_path_factory.mktemp("input_errors")
    cfg = write_config(d / "cfg.toml", run={"seeds": 2, "events": 40, "transient": 5},
                       integrator={"method": "ark4"})
    assert ensemble_here("run", cfg, "-o", d / "cat.h5").returncode == 0
    res = analysis_here("reduce", d / "cat.h5", "-o", d / "sum.h5", "--bootstrap", "20")
    assert res.returncode == 0, res.stderr
    data = (d / "cat.h5").read_bytes()
    (d / "head.h5").write_bytes(data[:4096])                                  # truncated catalog
    (d / "noise.h5").write_bytes(filekind.HDF5_SIGNATURE + os.urandom(5000))  # signature, then noise
    (d / "latin1.toml").write_bytes(b'[model]\nb = 20.0 # \xe9t\xe9\n')
    (d / "zeros.toml").write_bytes(bytes(100))
    (d / "dir.toml").mkdir()
    with h5py.File(d / "other.h5", "w") as h5:
        h5["x"] = [1, 2, 3]
    return d


# -- 1. config files that are not configs --------------------------------------------------

@pytest.mark.parametrize("name,words", [
    ("cat.h5", "is an event catalog (HDF5), not a TOML config"),
    ("sum.h5", "is a reduction summary (HDF5, reduced from"),
    ("head.h5", "damaged or truncated HDF5"),
    ("noise.h5", "damaged or truncated HDF5"),
    ("other.h5", "neither an event catalog nor a reduction summary"),
    ("dir.toml", "is a directory, not a TOML config"),
    ("latin1.toml", "not UTF-8 text (byte 0xe9"),
    ("zeros.toml", "binary data"),
    ("cfg.toml/x", "cannot be read (Not a directory)"),
])
def test_load_says_what_a_non_config_is(files, name, words):
    with pytest.raises(ConfigError) as err:
        load(files / name)
    message = str(err.value)
    assert str(files / name) in message and words in message and "\n" not in message


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads any file")
def test_load_unreadable_config(files, tmp_path):
    path = shutil.copy(files / "cfg.toml", tmp_path / "locked.toml")
    os.chmod(path, 0)
    with pytest.raises(ConfigError, match="locked.toml cannot be read"):
        load(path)


@pytest.mark.parametrize("command", ["validate", "run"])
@pytest.mark.parametrize("name", ["cat.h5", "dir.toml", "latin1.toml"])
def test_cli_non_config_is_one_line_exit_2(files, command, name):
    out = ["-o", files / "never.h5"] if command == "run" else []
    line = one_error_line(run("ensemble", command, files / name, *out), 2)
    assert str(files / name) in line
    assert not (files / "never.h5").exists()


# -- 2. every float key must be finite ------------------------------------------------------

FLOAT_KEYS = [(s, f.name) for s, cls in SECTIONS.items() for f in fields(cls) if f.type is float]


def test_every_float_key_is_checked():
    """FLOAT_KEYS comes from the dataclasses, so a new float key is tested without a change here."""
    assert {("model", "l"), ("model", "nu"), ("model", "a"), ("model", "b"), ("run", "init_stress"),
            ("run", "poll_seconds"), ("integrator", "atol"), ("integrator", "max_step"),
            ("integrator", "max_duration"), ("output", "flush_seconds"),
            ("output", "progress_seconds")} <= set(FLOAT_KEYS)


@pytest.mark.parametrize("section,key", FLOAT_KEYS)
@pytest.mark.parametrize("value", ["inf", "-inf", "nan", "1e400"])
def test_non_finite_float_refused_in_file_and_override(section, key, value):
    with pytest.raises(ConfigError, match=rf"^{section}\.{key} must be a finite number"):
        loads(f"[{section}]\n{key} = {value}\n")
    with pytest.raises(ConfigError, match=rf"^src: {section}\.{key} must be a finite number.*"
                                          rf"from --set {section}\.{key}={value}"):
        loads("", [f"{section}.{key}={value}"], source="src")


@pytest.mark.parametrize("key", [f.name for f in fields(SECTIONS["model"]) if f.type is float])
def test_non_finite_sweep_value_refused(key):
    with pytest.raises(ConfigError, match=rf"^sweep\.{key} must be a finite number, got inf"):
        loads(f"[sweep]\n{key} = [0.5, inf]\n")   # 0.5: within every key's range (model.sigma's is (0, 1))
    with pytest.raises(ConfigError, match=rf"sweep\.{key} must be a finite number, got nan.*--set"):
        loads("", [f"sweep.{key}=[0.5, nan]"])


def test_a_count_written_as_a_float_that_is_an_integer_is_that_integer():
    """Counts as the docs write them (2e5 events): an exact integer as a float is taken; 1.5 is not."""
    assert loads("[run]\nevents = 2e5\n").run.events == 200000
    assert loads("", ["run.events=3e3", "run.seeds=2.0"]).run.events == 3000
    with pytest.raises(ConfigError, match=r"run\.events must be an integer, got 1500\.5"):
        loads("[run]\nevents = 1500.5\n")


def test_integer_beyond_64_bits_refused():
    with pytest.raises(ConfigError, match="run.events must fit in 64 bits"):
        loads("[run]\nevents = 100000000000000000000\n")
    with pytest.raises(ConfigError, match="model.b must be a finite number"):
        loads("[model]\nb = 1" + "0" * 400 + "\n")


@pytest.mark.parametrize("text,named", [
    ("[model]\nl = 1e160\n", "model.l = 1e+160: l^2"),
    ("[model]\nb = 1e300\nnu = 1e-10\n", "model.b = 1e+300, model.nu = 1e-10"),      # b/nu = 1e310
    ("[model]\nb = 1e303\nnu = 1e-5\n", "model.b = 1e+303, model.nu = 1e-05"),       # (b/nu) ln(b/nu)
    ("[model]\nb = 1e-308\nnu = 10.0\n", "model.b = 1e-308, model.nu = 10.0"),  # nu/b
    ("[model]\nnu = 1e-10\n[run]\ninit_stress = 1e300\n", "run.init_stress = 1e+300"),
    ("[model]\nnu = 1e-300\n[sweep]\nb = [20.0, 1e10]\n", "sweep.b = 10000000000.0, model.nu = 1e-300"),
])
def test_parameter_points_that_overflow_are_refused(text, named):
    with pytest.raises(ConfigError, match="overflows a float") as err:
        loads(text)
    assert named in str(err.value)


@pytest.mark.parametrize("text", [
    "[model]\nl = 1e150\n",
    "[model]\nb = 1e300\nnu = 1e-5\n",
    "[model]\nnu = 1e-10\nb = 100.0\nc = 1e6\n",     # the hard cases of benchmarks/hard_cases.py
    "[model]\nnu = 1e-6\na = 30.0\n",
    "[model]\nnu = 1e-300\n",
])
def test_extreme_but_representable_points_pass(text):
    loads(text)


def test_cli_inf_override_is_one_line_exit_2(files):
    line = one_error_line(run("ensemble", "validate", files / "cfg.toml", "--set", "model.b=inf"), 2)
    assert "model.b must be a finite number, got inf" in line and "cfg.toml" in line


# -- 3. loads: stored text with overrides ---------------------------------------------------

def test_loads_applies_overrides_like_load(files):
    text = (files / "cfg.toml").read_text()
    overrides = ["model.b=30", "run.seeds=3", "sweep.a=[0.0, 1.0]"]
    assert loads(text, overrides) == load(files / "cfg.toml", overrides)
    assert loads(text, overrides).model.b == 30.0


def test_loads_names_its_source():
    with pytest.raises(ConfigError, match=r"^the config stored in x\.h5: model\.N must be an integer in \[1, "):
        loads("[model]\nN = 0\n", source="the config stored in x.h5")
    with pytest.raises(ConfigError, match=r"^stored: not valid TOML"):
        loads("[model\n", source="stored")
    with pytest.raises(ConfigError, match=r"^--set expects section.key=value"):   # not the text's fault
        loads("", ["model.b"], source="stored")


# -- 4. file kinds --------------------------------------------------------------------------

@pytest.mark.parametrize("name,kind", [
    ("cat.h5", "catalog"), ("sum.h5", "summary"), ("other.h5", "hdf5"), ("head.h5", "damaged"),
    ("noise.h5", "damaged"), ("cfg.toml", "config"), ("dir.toml", "directory"), ("nope.h5", "missing"),
    ("zeros.toml", "other"), ("latin1.toml", "other"),
])
def test_identify(files, name, kind):
    assert filekind.identify(files / name)[0] == kind


def test_identify_toml_empty_fifo_and_old_summary(files, tmp_path):
    (tmp_path / "t.toml").write_text('title = "not a run config"\n')
    assert filekind.identify(tmp_path / "t.toml")[0] == "toml"
    (tmp_path / "empty").write_bytes(b"")
    assert filekind.identify(tmp_path / "empty")[0] == "empty"
    os.mkfifo(tmp_path / "fifo")
    assert filekind.identify(tmp_path / "fifo")[0] == "special"    # and did not block opening it
    old = shutil.copy(files / "sum.h5", tmp_path / "old.h5")
    with h5py.File(old, "r+") as h5:
        assert h5.attrs["format"] == summary.FORMAT
        del h5.attrs["format"]          # as written before summaries carried one
    assert filekind.identify(old) == ("summary", f"reduced from {files / 'cat.h5'}")


def test_require_says_what_to_give_instead(files):
    with pytest.raises(filekind.FileKindError) as err:
        filekind.require(files / "sum.h5", "catalog")
    assert str(err.value) == (f"{files / 'sum.h5'} is a reduction summary (HDF5, reduced from "
                              f"{files / 'cat.h5'}), not an event catalog (give the catalog it was "
                              "reduced from)")
    with pytest.raises(summary.SummaryError, match="reduce it first: python -m analysis reduce"):
        filekind.require(files / "cat.h5", "summary", summary.SummaryError)
    filekind.require(files / "cat.h5", "catalog")


@pytest.mark.parametrize("command,name,words", [
    ("report", "cat.h5", "is an event catalog (HDF5), not a reduction summary (reduce it first"),
    ("report", "cfg.toml", "is a run config (TOML), not a reduction summary"),
    ("report", "dir.toml", "is a directory, not a reduction summary"),
    ("report", "head.h5", "is a damaged or truncated HDF5 file"),
    ("plot", "cat.h5", "is an event catalog (HDF5), not a reduction summary"),
    ("plot", "noise.h5", "is a damaged or truncated HDF5 file"),
    ("reduce", "sum.h5", "is a reduction summary (HDF5, reduced from"),
    ("reduce", "cfg.toml", "is a run config (TOML), not an event catalog (run it first"),
    ("reduce", "dir.toml", "is a directory, not an event catalog"),
    ("reduce", "head.h5", "is a damaged or truncated HDF5 file"),
    ("reduce", "noise.h5", "is a damaged or truncated HDF5 file"),
    ("reduce", "nope.h5", "does not exist"),
])
def test_analysis_wrong_file_is_one_line_exit_1(files, tmp_path, command, name, words):
    extra = {"plot": ["--figure", "magnitude", "-o", tmp_path / "x.png"],
             "reduce": ["-o", tmp_path / "x.summary.h5"], "report": []}[command]
    line = one_error_line(run("analysis", command, files / name, *extra), 1)
    assert f"{files / name} {words}" in line


@pytest.mark.parametrize("name,dataset,command,noun", [
    ("sum.h5", "points/peaks", "report", "reduction summary"),
    ("cat.h5", "events/mu", "reduce", "event catalog"),
])
def test_damaged_object_inside_an_hdf5_file_is_one_line(files, tmp_path, name, dataset, command, noun):
    """The file opens and says what it is; one dataset's header is garbage. Not a traceback."""
    with h5py.File(files / name, "r") as h5:
        header = h5py.h5o.get_info(h5[dataset].id).addr
    kind = filekind.identify(files / name)[0]
    data = bytearray((files / name).read_bytes())
    data[header:header + 64] = b"\xff" * 64
    hollow = tmp_path / "hollow.h5"
    hollow.write_bytes(data)
    assert filekind.identify(hollow)[0] == kind
    line = one_error_line(run("analysis", command, hollow), 1)
    assert line.startswith(f"error: {hollow}: ") and "damaged" in line


def damage_row(src, dst, task, row, **values):
    shutil.copy(src, dst)
    with h5py.File(dst, "r+") as h5:
        per_task = h5["events/t"].shape[0] // h5["tasks/point"].shape[0]
        for name, value in values.items():
            h5["events"][name][task * per_task + row] = value
    return dst


@pytest.mark.parametrize("values,words", [
    ({"epicenter": 10**6}, "epicenter 1000000 outside the chain of 60 blocks"),
    ({"t": math.nan}, "time nan"),
    ({"t": -1.0}, "time -1.0 before the event ahead of it"),
    ({"mu": math.inf}, "magnitude inf"),
])
def test_reduce_refuses_rows_no_run_writes(files, tmp_path, values, words):
    bad = damage_row(files / "cat.h5", tmp_path / "bad.h5", 1, 7, **values)
    line = one_error_line(run("analysis", "reduce", bad, "-o", tmp_path / "s.h5"), 1)
    assert f"{bad}: task 1: event 7: {words}" in line
    assert not (tmp_path / "s.h5").exists()


def test_reduce_does_not_trust_the_events_written_mirror(files, tmp_path):
    """/tasks/events_written is a mirror: the checksummed commit rows say what a task holds, and a mirror
    that matches none of them is a damaged catalog (ensemble/store/tables.py), never a count to use."""
    _, tasks, _ = reader.read_tasks(files / "cat.h5")
    assert tasks["events_written"][1] == 40
    bad = shutil.copy(files / "cat.h5", tmp_path / "bad.h5")
    with h5py.File(bad, "r+") as h5:
        h5["tasks/events_written"][1] = 41
    with pytest.raises(CatalogError, match=r"task 1: /tasks/events_written 41 matches none of its commit rows"):
        reader.read_tasks(bad)


def test_reduce_force_replaces_only_a_summary(files, tmp_path):
    """An output path is a usage error (exit 2, as `ensemble run` says of an existing catalog)."""
    victim = shutil.copy(files / "cat.h5", tmp_path / "victim.h5")
    before = victim.read_bytes()
    line = one_error_line(run("analysis", "reduce", files / "cat.h5", "-o", victim, "--force"), 2)
    assert "--force replaces only a reduction summary" in line
    line = one_error_line(run("analysis", "reduce", files / "cat.h5", "-o", files / "cat.h5", "--force"), 2)
    assert f"would overwrite the command's input {files / 'cat.h5'}" in line
    assert victim.read_bytes() == before
    res = run("analysis", "reduce", files / "cat.h5", "-o", files / "sum.h5")   # exists, no --force
    assert "--force" in one_error_line(res, 2)


# -- 5. one failing rank aborts every rank --------------------------------------------------

@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="mpiexec not found")
def test_reduce_failing_on_one_rank_aborts_all(files, tmp_path):
    """Rank 1 reduces task 1, whose rows are damaged, while rank 0 waits for it in gather.

    Without the abort rank 0 would wait for ever: the timeout fails that (no bound on how long
    the abort takes here, which a loaded machine stretches).
    """
    bad = damage_row(files / "cat.h5", tmp_path / "bad.h5", 1, 7, epicenter=10**6)
    res = run_bounded(["mpiexec", "-n", "2", sys.executable, "-m", "analysis", "reduce", bad, "-o", tmp_path / "s.h5"],
                      TIMEOUT, env=child_env())
    assert res.returncode != 0
    assert "error: rank 1: " in res.stderr and "task 1: event 7: epicenter 1000000" in res.stderr
    assert not (tmp_path / "s.h5").exists()


# -- 6. a closed stdout ends quietly --------------------------------------------------------

def run_into_closed_pipe(package, *args, buffered):
    """Run with stdout a pipe whose reader closed before the command wrote anything.

    buffered: stdout block-buffered as usual (the error comes at the final flush), or
    PYTHONUNBUFFERED (it comes inside the print)."""
    environ = child_env()
    environ.pop("PYTHONUNBUFFERED", None)
    if not buffered:
        environ["PYTHONUNBUFFERED"] = "1"
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        return run_bounded([sys.executable, "-m", package, *args], TIMEOUT, stdout=write_end, env=environ)
    finally:
        os.close(write_end)


@pytest.mark.parametrize("buffered", [True, False])
@pytest.mark.parametrize("package,args", [
    ("ensemble", ["status", "cat.h5"]),
    ("ensemble", ["validate", "cfg.toml"]),
    ("analysis", ["report", "sum.h5"]),
])
def test_closed_pipe_exits_141_without_traceback(files, package, args, buffered):
    res = run_into_closed_pipe(package, *[files / a if a.endswith((".h5", ".toml")) else a for a in args],
                               buffered=buffered)
    assert res.returncode == 141 and res.stderr == ""


def test_reader_closing_after_first_line(files):
    """Like `| head -1`, with more output than the pipe holds, so the writer meets the closed end."""
    sweep = "sweep.b=[" + ", ".join(f"{20 + i / 100:.2f}" for i in range(3000)) + "]"
    # the reader keeps the first line and closes the pipe
    with Started([sys.executable, "-m", "ensemble", "validate", files / "cfg.toml", "--set", sweep],
                 env=child_env(), separate_stderr=True, stdout_lines=1) as proc:
        code = proc.wait(TIMEOUT)
    assert proc.lines == ["[model]\n"]
    assert code == 141 and proc.errors == ""


def test_analysis_main_lets_a_broken_pipe_through(files, monkeypatch):
    """Not turned into 'error: [Errno 32] Broken pipe', exit 1, as a file error."""
    from analysis.cli import main

    class Closed:
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            pass

    monkeypatch.setattr(sys, "stdout", Closed())
    with pytest.raises(BrokenPipeError):
        main(["report", str(files / "sum.h5")])


class OneRank:
    """The part of an MPI communicator the guards use, for one rank without MPI."""

    def Get_rank(self):
        return 0

    def Get_size(self):
        return 1

    def bcast(self, value, root=0):
        return value

    def Abort(self, code):
        raise AssertionError("a lone rank has nobody to abort")


def test_run_guarded_codes_and_messages(capsys):
    from ensemble.run.abort import on_root, run_guarded
    codes = {ConfigError: 2, summary.SummaryError: 1}

    def body(error):
        def raising():
            raise error
        return lambda: on_root(OneRank(), raising, tuple(codes))

    assert run_guarded(OneRank(), lambda: 0, codes) == 0
    assert run_guarded(OneRank(), body(ConfigError("model.b must be > 0")), codes) == 2
    assert capsys.readouterr().err == "error: model.b must be > 0\n"
    assert run_guarded(OneRank(), body(summary.SummaryError("x.h5 exists")), codes) == 1
    assert run_guarded(OneRank(), body(ZeroDivisionError("float division by zero")), codes) == 1
    assert capsys.readouterr().err == "error: x.h5 exists\nerror: rank 0: float division by zero\n"
    with pytest.raises(BrokenPipeError):   # left to __main__, which ends quietly
        run_guarded(OneRank(), body(BrokenPipeError(32, "Broken pipe")), codes)
