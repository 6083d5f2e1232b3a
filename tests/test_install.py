"""scripts/stack.py finds an MPI compiler and a parallel HDF5 where clusters put them;
scripts/setup.sh refuses STACK=parallel without them before it changes anything, chooses the
stack a new .venv gets, and says what it does while it does it; and every entry point takes the
one numba cache of the package (ensemble/kernel_cache.py), so the kernels compile once (that the Quick
start's run after `make run` on a fresh clone compiles nothing is tests/install_paths.sh's check, in CI).

The machine's own stack is not used: each case builds the places a module system, Spack or a
virtual environment would (executables, include/H5pubconf.h, .pc files) in a temporary directory,
and runs the detection with a PATH of only those and the few programs it needs. setup.sh's choices
and messages are checked against a stand-in for .venv's python (FAKE_PYTHON), which installs
nothing. The installs themselves (the wheel stack as a non-root user, the parallel stack from
Debian) are run by tests/install_paths.sh (wheels, modules) and `make test` in CI.
"""
import os
import re
import shutil
import subprocess
import sys

import pytest

from ensemble import kernel_cache
from ensemble.slurm.options import JobOptions
from ensemble.slurm.render import render

from .conftest import write_config
from .processes import ROOT, child_env, run_bounded

sys.path.insert(0, str(ROOT / "scripts"))
import stack  # (scripts/ is not a package: setup.sh runs it before .venv exists)

PARALLEL_HEADER = "#define H5_HAVE_PARALLEL 1\n#define H5_VERSION \"1.14.5\"\n"
SERIAL_HEADER = "/* #undef H5_HAVE_PARALLEL */\n#define H5_VERSION \"1.14.5\"\n"


def executable(path, text="#!/bin/sh\nexit 0\n"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    path.chmod(0o755)
    return path


def hdf5_prefix(root, header):
    (root / "include").mkdir(parents=True)
    (root / "lib").mkdir()
    (root / "include" / "H5pubconf.h").write_text(header)
    return root


def tools(tmp_path, *names):
    """A bin directory with links to the named programs of this machine (those it has)."""
    bin_dir = tmp_path / "tools"
    bin_dir.mkdir(exist_ok=True)
    for name in names:
        found = shutil.which(name)
        if found:
            (bin_dir / name).symlink_to(found)
    return bin_dir


def env_with(*path, **variables):
    return {"PATH": os.pathsep.join(map(str, path)), **{k: str(v) for k, v in variables.items()}}


def test_a_module_system_prefix_in_hdf5_dir(tmp_path):
    mpicc = executable(tmp_path / "openmpi" / "bin" / "mpicc")
    prefix = hdf5_prefix(tmp_path / "hdf5-mpi", PARALLEL_HEADER)
    out, notes = stack.detect(env_with(mpicc.parent, HDF5_DIR=prefix))
    assert out["STACK_FOUND"] == "1", notes
    assert out["STACK_MPICC"] == str(mpicc)
    assert out["STACK_H5PY_ENV"] == f"HDF5_DIR={prefix}"


def test_hdf5_root_as_spack_sets_it_and_mpicc_from_the_environment_variable(tmp_path):
    mpicc = executable(tmp_path / "spack" / "mpich" / "bin" / "mpicc")
    prefix = hdf5_prefix(tmp_path / "spack" / "hdf5", PARALLEL_HEADER)
    out, notes = stack.detect(env_with(tmp_path, MPICC=mpicc, HDF5_ROOT=prefix))
    assert out["STACK_FOUND"] == "1", notes
    assert (out["STACK_MPICC"], out["STACK_H5PY_ENV"]) == (str(mpicc), f"HDF5_DIR={prefix}")


def test_a_serial_hdf5_is_not_taken_and_the_message_says_what_is_missing(tmp_path):
    mpicc = executable(tmp_path / "bin" / "mpicc")
    serial = hdf5_prefix(tmp_path / "hdf5-serial", SERIAL_HEADER)
    out, notes = stack.detect(env_with(mpicc.parent, HDF5_DIR=serial))
    assert out["STACK_FOUND"] == "0"
    assert "parallel HDF5" in out["STACK_MISSING"] and "MPI C compiler" not in out["STACK_MISSING"]
    assert f"HDF5_DIR={serial}: serial (no H5_HAVE_PARALLEL)" in notes


def test_h5pcc_on_path_names_its_installation_point(tmp_path):
    prefix = hdf5_prefix(tmp_path / "hdf5", PARALLEL_HEADER)
    bin_dir = tmp_path / "hdf5" / "bin"
    executable(bin_dir / "h5pcc", "#!/bin/sh\necho '             Installation point: "
               f"{prefix}'\necho '                   Parallel HDF5: yes'\n")
    executable(bin_dir / "mpicc")
    out, notes = stack.detect(env_with(bin_dir))
    assert out["STACK_FOUND"] == "1", notes
    assert out["STACK_H5PY_ENV"] == f"HDF5_DIR={prefix}"


@pytest.mark.skipif(shutil.which("pkg-config") is None, reason="pkg-config is not installed")
def test_pkg_config_finds_the_parallel_one_among_several(tmp_path):
    serial = hdf5_prefix(tmp_path / "serial", SERIAL_HEADER)
    parallel = hdf5_prefix(tmp_path / "openmpi", PARALLEL_HEADER)
    pc = tmp_path / "pc"
    pc.mkdir()
    for name, prefix in (("hdf5", serial), ("hdf5-openmpi", parallel)):
        (pc / f"{name}.pc").write_text(f"includedir={prefix}/include\nName: {name}\nDescription: x\n"
                                       f"Version: 1.14.5\nCflags: -I${{includedir}}\n")
    executable(tmp_path / "bin" / "mpicc")
    out, notes = stack.detect(env_with(tmp_path / "bin", tools(tmp_path, "pkg-config"), PKG_CONFIG_LIBDIR=pc))
    assert out["STACK_FOUND"] == "1", notes
    assert out["STACK_H5PY_ENV"] == "HDF5_PKGCONFIG_NAME=hdf5-openmpi"
    assert "pkg-config hdf5-mpich: not known" in notes


def test_the_mpich_wheels_mpicc_in_a_virtual_environment_is_not_taken(tmp_path):
    venv = tmp_path / "venv"
    executable(venv / "bin" / "mpicc")
    (venv / "pyvenv.cfg").write_text("home = /usr/bin\n")
    system = executable(tmp_path / "usr" / "bin" / "mpicc")
    out, notes = stack.detect(env_with(venv / "bin", system.parent))
    assert out["STACK_MPICC"] == str(system), notes
    out, _ = stack.detect(env_with(venv / "bin"))
    assert out["STACK_MPICC"] == "" and "MPI C compiler" in out["STACK_MISSING"]


def setup_copy(tmp_path):
    """The setup scripts in a directory of their own (setup.sh works in its repository's root)."""
    repo = tmp_path / "repo"
    (repo / "scripts").mkdir(parents=True)
    for name in ("setup.sh", "stack.py"):
        shutil.copy(ROOT / "scripts" / name, repo / "scripts" / name)
    return repo


def run_setup(repo, path, **variables):
    env = {"PATH": os.pathsep.join(map(str, path)), "HOME": str(repo), "PYTHON": sys.executable, **variables}
    return subprocess.run([shutil.which("bash"), str(repo / "scripts" / "setup.sh")], env=env, capture_output=True,
                          text=True, timeout=120)


def test_stack_parallel_without_one_stops_before_touching_the_environment(tmp_path):
    """No mpicc, no HDF5, no apt-get on PATH: a clear message, exit 1, no .venv made."""
    repo = setup_copy(tmp_path)
    res = run_setup(repo, [tools(tmp_path, "dirname", "id", "cat", "rm")], STACK="parallel")
    assert res.returncode == 1, res.stdout + res.stderr
    line = res.stderr.strip().splitlines()[-1]
    assert line.startswith("setup: error: STACK=parallel: no parallel HDF5 stack: missing an MPI C compiler")
    assert "docs/install.md" in line and "STACK=wheels" in line
    assert not (repo / ".venv").exists()


def test_an_unknown_stack_is_an_error_naming_it(tmp_path):
    res = run_setup(setup_copy(tmp_path), [tools(tmp_path, "dirname")], STACK="conda")
    assert res.returncode == 1
    assert res.stderr.strip() == "setup: error: STACK=conda: must be auto, parallel or wheels"


# -- what setup.sh says, and which stack it takes -----------------------------------------------

# .venv's python as setup.sh calls it, installing nothing: `pip install -e` (the project) takes
# FAKE_PIP_SECONDS, other pip installs none; every import works; h5py has MPI only with FAKE_MPI_H5PY.
FAKE_PYTHON = """#!/bin/sh
case "$*" in
  "-m pip install"*" -e "*) sleep "${FAKE_PIP_SECONDS:-0}" ;;
  *"get_config().mpi"*) [ -n "$FAKE_MPI_H5PY" ] ;;
esac
"""
SETUP_TOOLS = ("dirname", "id", "cat", "rm", "sleep", "tail", "sed", "touch", "mktemp", "timeout", "env")


def fake_setup(tmp_path, *path, timeout=120, **variables):
    """setup.sh in a copy whose .venv holds FAKE_PYTHON, run with PATH = path + a few tools."""
    repo = tmp_path / "repo"
    if not repo.exists():     # the first run of a test
        setup_copy(tmp_path)
        executable(repo / ".venv" / "bin" / "python", FAKE_PYTHON)
        tools(tmp_path, *SETUP_TOOLS)
    env = {"PATH": os.pathsep.join(map(str, [*path, tmp_path / "tools"])), "HOME": str(repo),
           "PYTHON": sys.executable, **variables}
    res = run_bounded([shutil.which("bash"), repo / "scripts" / "setup.sh"], timeout, env=env)
    assert res.returncode == 0, res.stdout + res.stderr
    return repo, res.stdout.splitlines()


def test_setup_numbers_its_stages_with_the_time_and_beats_during_a_long_step(tmp_path):
    _, lines = fake_setup(tmp_path, STACK="wheels", SETUP_HEARTBEAT="1", FAKE_PIP_SECONDS="4")
    stages = [line for line in lines if re.fullmatch(r"setup: \[\d/\d\] .* \(elapsed \d+:\d\d\)", line)]
    assert [line[:12] for line in stages] == ["setup: [1/4]", "setup: [2/4]", "setup: [3/4]", "setup: [4/4]"], lines
    assert "installing the project" in stages[2] and "compiling the kernels of every friction law" in stages[3]
    # the 4 s step is not silent: a line every second, after its stage line
    beats = [i for i, line in enumerate(lines)
             if re.fullmatch(r"setup:   \.\.\. still installing the project, \d+:\d\d elapsed", line)]
    assert beats and min(beats) > lines.index(stages[2]), lines
    assert re.fullmatch(r"setup: ok: stack wheels \(\d+:\d\d\)", lines[-1]), lines


def test_the_heartbeat_ends_with_its_step_and_holds_no_pipe_open(tmp_path):
    """A beat every 10 minutes: if its sleep outlived the step with setup's stdout, the pipe this
    test reads (as `make setup | tee log` does) would stay open until the deadline, failing it."""
    _, lines = fake_setup(tmp_path, timeout=60, STACK="wheels", SETUP_HEARTBEAT="600", FAKE_PIP_SECONDS="1")
    assert lines[-1].startswith("setup: ok: stack wheels"), lines
    assert not any("still" in line for line in lines), lines


def test_auto_gives_a_new_venv_the_wheels_and_names_the_parallel_stack_it_could_build(tmp_path):
    mpicc = executable(tmp_path / "mpi" / "bin" / "mpicc")
    prefix = hdf5_prefix(tmp_path / "hdf5-mpi", PARALLEL_HEADER)
    repo, lines = fake_setup(tmp_path, mpicc.parent, HDF5_DIR=prefix)
    text = "\n".join(lines)
    assert f"a parallel HDF5 stack is on this machine ({mpicc}, HDF5_DIR={prefix})" in text
    assert "make setup STACK=parallel" in text and "building" not in text
    assert lines[-1].startswith("setup: ok: stack wheels")
    assert (repo / ".venv" / "ensemble-stack").read_text() == "wheels\n"
    # a parallel .venv that no longer imports (here: its h5py has no MPI) is rebuilt, falling back to wheels
    (repo / ".venv" / "ensemble-stack").write_text("parallel\n")
    _, lines = fake_setup(tmp_path, mpicc.parent, HDF5_DIR=prefix)
    text = "\n".join(lines)
    assert re.search(r"setup: \[2/6\] building mpi4py against .*mpicc \(elapsed", text), text
    assert "h5py was built but has no MPI support" in text and lines[-1].startswith("setup: ok: stack wheels")
    # STACK=parallel builds it (make test)
    _, lines = fake_setup(tmp_path, mpicc.parent, HDF5_DIR=prefix, STACK="parallel", FAKE_MPI_H5PY="1")
    assert lines[-1].startswith("setup: ok: stack parallel"), lines


# -- one numba cache for every entry point ------------------------------------------------------

# where the chain kernels and the reduction's scan kernel are cached, imported in this order (the
# reduction first, as `python -m analysis` imports it)
CACHE_PROBE = ("import analysis.recurrence as r, ensemble.model.chain as c; "
               "print(c.simulate._cache._cache_path); print(r.scan._cache._cache_path)")


def without_cache_variable():
    return {k: v for k, v in child_env().items() if k != "NUMBA_CACHE_DIR"}


def test_every_entry_point_takes_the_packages_kernel_cache(tmp_path, monkeypatch):
    env = without_cache_variable()
    probe = tmp_path / "probe.py"
    probe.write_text(CACHE_PROBE.replace("; ", "\n"))
    base = kernel_cache.base(env)
    assert base == str(ROOT / ".numba_cache")     # an editable install: the checkout's
    seen = {}
    for target in ("run", "quick"):     # the Makefile's environment (-o setup: not set up again)
        res = run_bounded(["make", "-s", "-C", ROOT, "-o", "setup", target, f"PY={sys.executable} {probe}"], 300,
                          env=env)
        assert res.returncode == 0, res.stdout + res.stderr
        seen[f"make {target}"] = res.stdout.split()
    # python -m ensemble / -m analysis from a user's directory
    res = run_bounded([sys.executable, "-c", CACHE_PROBE], 300, cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stderr
    seen["python"] = res.stdout.split()
    for where, (chain, scan) in seen.items():
        assert chain.startswith(base + os.sep) and scan.startswith(base + os.sep), (where, chain, scan)
    assert len({tuple(paths) for paths in seen.values()}) == 1, seen
    # the commands the tests start, and the Slurm jobs (they set no cache of their own by default)
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    assert child_env()["NUMBA_CACHE_DIR"] == base
    cfg = write_config(tmp_path / "tiny.toml")
    from ensemble.config import load
    job = render(load(cfg), JobOptions(), tmp_path / "job")
    for script in (job.run_script, job.reduce_script):
        assert "export NUMBA_CACHE_DIR" not in script.read_text(), script
