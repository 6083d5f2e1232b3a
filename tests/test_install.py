"""scripts/stack.py finds an MPI compiler and a parallel HDF5 where clusters put them, and
scripts/setup.sh refuses STACK=parallel without them before it changes anything.

The machine's own stack is not used: each case builds the places a module system, Spack or a
virtual environment would (executables, include/H5pubconf.h, .pc files) in a temporary directory,
and runs the detection with a PATH of only those and the few programs it needs. The installs
themselves (the wheel stack as a non-root user, the parallel stack from Debian) are run by
tests/install_paths.sh (wheels, modules) and `make test` in CI.
"""
import os
import shutil
import subprocess
import sys

import pytest

from .processes import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
import stack  # noqa: E402  (scripts/ is not a package: setup.sh runs it before .venv exists)

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
