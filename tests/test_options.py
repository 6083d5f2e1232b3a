"""Every numeric option and every output path of every analysis command, attacked.

Each numeric option of each subcommand (found in the parser itself, so that a new one is
attacked too) is given NaN, infinities and sizes no machine holds; each output path a missing
or unwritable folder, the command's own input, a name that is not UTF-8 and an existing file
without --force. Every one must end before any work with exit 2 and one stderr line naming the
option or the path (ensemble/checks.py), and write nothing. The commands run in this process
(analysis.cli.main), a few through `python -m analysis` as a user types them.
"""
import argparse
import os
import shutil
import sys
import time

import pytest

from analysis import cli, options
from ensemble.model import laws
from ensemble import checks

from .processes import ROOT, child_env, run_bounded
from .test_reduction import CONFIG, N_CHAIN, write_catalog

SWEEP = "nu = [1.0]"
# options that are not numbers: the parser's own, and these
NOT_NUMERIC = {"help", "output", "title", "figure", "format", "force", "partial", "region"}

# bad values of each numeric option (argparse dest): non-finite, beyond any honest range, not an integer
BAD = {
    "mu_c": ["nan", "inf", "-inf", "1e400", "1e300", "x"],
    "b_cut": ["nan", "inf", "-inf", "1e400", "-1e300"],
    "level": ["nan", "inf", "0", "1", "1e300", "-0.5"],
    "window": ["nan", "inf", "1e400", "-1", "123456789012345678901234567890", "2.5"],
    "bootstrap": ["nan", "inf", "0", "1000001", "10" + "0" * 30],
    "blocks": ["nan", "inf", "0", "1000001", "10" + "0" * 30],
    "seed": ["nan", "inf", "-1", str(2 ** 63), "10" + "0" * 30],
    "n_large": ["nan", "inf", "1", "10" + "0" * 30],
    "n_min": ["nan", "inf", "0", "10" + "0" * 30],
    "mu_bins": ["nan:7:70", "0:inf:70", "-inf:7:70", "0:7:nan", "0:7:0", "7:0:70", "0:7", "0:7:1e400",
                "0:1e308:10000000000", "-1e308:1e308:10"],
    "tnu_bins": ["nan:2000:80", "0:inf:80", "0:2000:inf", "0:1e308:10000000000", "2000:0:80", "0:0:80"],
    "creep_mu_bins": ["nan:3:75", "-12:inf:75", "-12:3:0", "3:-12:75", "-12:3", "-1e308:1e308:10"],
    "creep_duration_bins": ["-7:nan:50", "-inf:3:50", "-7:3:1e400", "-7:-7:50", "0:1e308:10000000000"],
    "seis_time_bins": ["-1000:nan:40", "-inf:1000:40", "1000:-1000:40", "-1000:1000:0", "0:1e308:10000000000"],
    "seis_distance_bins": ["0:nan:20", "0:40", "40:0:20", "0:40:1e400"],
    "seis_near": ["nan", "inf", "-1", "1e400", "x"],
    "seis_ring": ["nan", "inf", "-1", "1e400"],
    "seis_short": ["nan", "inf", "-1", "1e400"],
    "afterslip_window": ["nan", "inf", "-1", "1e400", "x"],
    "seis_long": ["nan", "inf", "-0.5", "1e400"],
    "lr_bins": ["0.5:nan:20", "0:1600", "1600:0:20", "0:1600:0", "0:1e308:10000000000"],
    "lr_min": ["nan", "inf", "0", "-3", "2.5", "10" + "0" * 30],
    "lr_max": ["nan", "inf", "0", "10" + "0" * 30],
    "class_min": ["nan", "inf", "0", "x"],
    "uni_edge": ["nan", "inf", "-0.1", "0.6", "x"],
    "region_span": ["nan", "inf", "0", "-1", "1e400", "x"],
    "region_skip": ["nan", "inf", "-1", "1e400", "x"],
    "task": ["nan", "inf", "-1", "2.5", "x", "10" + "0" * 30],
    "index": ["nan", "-1", "0.5", "x", "10" + "0" * 30],
}
ENV = child_env(PYTHONPATH=str(ROOT))   # this checkout's packages, wherever the command runs
OPTION = {dest: "--" + dest.replace("_", "-") for dest in BAD}


def subparsers():
    """{command: its argparse parser}."""
    action = next(a for a in cli._parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def numeric_options():
    """(command, dest) of every numeric option of every subcommand."""
    return [(command, a.dest) for command, p in subparsers().items() for a in p._actions
            if a.option_strings and a.dest not in NOT_NUMERIC]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A finished catalog (one point, two seeds), its summary, a config and a figure."""
    d = tmp_path_factory.mktemp("options")
    text = CONFIG.format(N=N_CHAIN, sweep=SWEEP, seeds=2, seed=3)
    write_catalog(d / "cat.h5", text, [400, 400], seed=1)
    (d / "cfg.toml").write_text(text)
    assert cli.main(["reduce", str(d / "cat.h5"), "-o", str(d / "sum.h5"), "--bootstrap", "20"]) == 0
    return d


def base_args(command, d, out):
    """A command line of `command` that works, writing `out`."""
    return {"reduce": ["reduce", d / "cat.h5", "-o", out, "--bootstrap", "5"],
            "compare": ["compare", d / "cat.h5", "-o", out, "--bootstrap", "5", "--n-large", "5"],
            "export": ["export", d / "cat.h5", "-o", out],
            "plot": ["plot", d / "sum.h5", "--figure", "magnitude", "-o", out],
            "report": ["report", d / "sum.h5"],
            "paper": ["paper", d / "sum.h5"],
            "history": ["history", d / "cat.h5", "-o", out]}[command]


def refused(capsys, argv, code=2):
    """The single stderr line of a command that must fail with `code` (in this process)."""
    capsys.readouterr()
    assert cli.main([str(a) for a in argv]) == code
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), out.err
    return lines[0]


def test_every_numeric_option_is_checked_and_attacked():
    """The class guard: a numeric option of any subcommand reaches a check of cli.NUMERIC as text
    (argparse's own type= would print a usage block, and would take "nan" for a float) and has bad
    values in this file."""
    found = numeric_options()
    assert {dest for _, dest in found} == set(cli.NUMERIC) == set(BAD)
    for command, p in subparsers().items():
        for a in p._actions:
            if a.option_strings and a.dest not in NOT_NUMERIC:
                assert a.type is None, (command, a.dest)
    assert {c for c, _ in found} == {"reduce", "compare", "history"}   # plot, export, paper, report: none


@pytest.mark.parametrize("command,dest,value", [(c, d, v) for c, d in numeric_options() for v in BAD[d]])
def test_a_bad_number_is_one_line_exit_2_naming_the_option(files, tmp_path, capsys, command, dest, value):
    out = tmp_path / "out"
    line = refused(capsys, base_args(command, files, out) + [f"{OPTION[dest]}={value}"])
    assert OPTION[dest] in line, line
    assert not out.exists()


def test_reduce_mu_c_nan_is_refused_by_the_command_line(files, tmp_path):
    """Issue 26, item 9, as a user types it: `--mu-c nan` exited 0 with inconsistent numbers."""
    for option, value in (("--mu-c", "nan"), ("--mu-c", "inf"), ("--b-cut", "nan")):
        res = run_bounded([sys.executable, "-m", "analysis", "reduce", str(files / "cat.h5"), "-o",
                           str(tmp_path / "s.h5"), option, value], 120, env=ENV)
        assert res.returncode == 2, res.stderr
        assert res.stderr.strip().splitlines() == [f"error: {option} must be finite, not '{value}'"]
        assert not (tmp_path / "s.h5").exists()


def test_huge_bins_are_refused_before_any_file_is_read(tmp_path):
    """Issue 26, item 12: `--tnu-bins 0:1e308:10000000000` allocated 74.5 GiB and exited 1. Refused
    as out of range with exit 2, before the catalog is read (it need not even exist)."""
    start = time.monotonic()
    res = run_bounded([sys.executable, "-m", "analysis", "reduce", str(tmp_path / "no such catalog.h5"),
                       "-o", str(tmp_path / "s.h5"), "--tnu-bins", "0:1e308:10000000000"], 120, env=ENV)
    assert res.returncode == 2, res.stderr
    assert res.stderr.strip().splitlines() == [
        "error: --tnu-bins n = '10000000000' is out of range [1, 1000000]"]
    assert time.monotonic() - start < 60


def test_options_that_together_outgrow_memory_are_refused(files, tmp_path, capsys):
    """Each within its range, together more than any machine holds: (tasks, stretches, bins) counts."""
    line = refused(capsys, ["reduce", files / "cat.h5", "-o", tmp_path / "s.h5", "--blocks", "1000000",
                            "--mu-bins", "0:7:1000000"])
    assert "--blocks 1000000" in line and "GiB of memory, more than this machine's" in line
    line = refused(capsys, ["compare", files / "cat.h5", "-o", tmp_path / "c", "--n-large", "5",
                            "--blocks", "1000000", "--bootstrap", "1000000"])
    assert "--blocks 1000000 and --bootstrap 1000000" in line
    assert not (tmp_path / "s.h5").exists() and not (tmp_path / "c").exists()


def test_memory_check_against_a_limit():
    assert checks.memory("x", 10, limit=10) == 10
    with pytest.raises(checks.UsageError, match=r"^x need about 1 GiB of memory, more than this machine's 0.5 GiB"):
        checks.memory("x", 2 ** 30, limit=2 ** 29)


def test_good_numbers_pass_and_are_converted(files, tmp_path, capsys):
    args = cli._parser().parse_args(["reduce", "c.h5", "--mu-c", "3.5", "--level", "0.9", "--seed", str(2 ** 63 - 1),
                                     "--tnu-bins", "0:2000:1000000", "--window", "0"])
    cli.check_numbers(args)
    assert (args.mu_c, args.level, args.seed, args.window, args.bootstrap) == (3.5, 0.9, 2 ** 63 - 1, 0, None)
    # the options record: what was given, converted, and the declared defaults (the law's where so declared)
    opt = options.make(scales=laws.get("aging").scales, **options.given(args))
    assert (opt.mu_c, opt.level, opt.seed, opt.window, opt.bootstrap, opt.b_cut) == (3.5, 0.9, 2 ** 63 - 1, 0, 1000,
                                                                                    3.0)
    assert len(opt.tnu_edges) == 1000001 and list(opt.mu_edges[:2]) == [0.0, 0.1]
    assert cli.main(["reduce", str(files / "cat.h5"), "-o", str(tmp_path / "s.h5"), "--mu-c", "3.5",
                     "--bootstrap", "5", "--seed", str(2 ** 63 - 1)]) == 0


# -- output paths ------------------------------------------------------------------------------

WRITERS = ("reduce", "export", "compare", "plot")   # the commands that write (paper, report print)
EXISTING = {"reduce": "sum2.h5", "plot": "fig.png", "export": "tables", "compare": "cmp"}


def existing_output(command, d):
    """An output of `command` already there (a summary, a figure, a table, a comparison)."""
    path = d / EXISTING[command]
    if command == "reduce":
        shutil.copy(d / "sum.h5", path)
    elif command == "plot":
        path.write_bytes(b"\x89PNG mine")
    else:
        path.mkdir()
        (path / ("events.csv" if command == "export" else "comparison.md")).write_text("mine\n")
    return path


def bad_outputs(command, d):
    """(case, the output path, extra options, what the line must name, what it must say)."""
    source = d / ("sum.h5" if command == "plot" else "cat.h5")
    odd = d / os.fsdecode(b"\xff-out")
    cases = [("input", source, [], str(source), "would overwrite the command's input"),
             ("input, --force", source, ["--force"], str(source), "would overwrite the command's input"),
             ("not UTF-8", odd, [], checks.shown(odd), "is not valid UTF-8"),
             ("under a file", d / "cfg.toml" / "out", [], str(d / "cfg.toml"), "is not a directory")]
    if command in ("reduce", "plot"):   # a file in a folder; export and compare make their folder
        cases.append(("missing folder", d / "missing_dir" / "x.out", [], f"directory {d / 'missing_dir'}",
                      "does not exist"))
    return cases


@pytest.mark.parametrize("command", WRITERS)
def test_a_bad_output_path_is_one_line_exit_2_naming_it(files, tmp_path, capsys, command):
    d = tmp_path
    for name in ("cat.h5", "sum.h5", "cfg.toml"):
        shutil.copy(files / name, d / name)
    for case, out, extra, named, words in bad_outputs(command, d):
        before = {p: p.read_bytes() for p in d.iterdir() if p.is_file()}
        line = refused(capsys, base_args(command, d, out) + extra)
        assert named in line and words in line, (case, line)
        assert {p: p.read_bytes() for p in d.iterdir() if p.is_file()} == before, case
        assert not (d / "missing_dir").exists()
    # existing, without --force: refused, untouched; with it, replaced
    out = existing_output(command, d)
    inside = (out / ("events.csv" if command == "export" else "comparison.md")) if out.is_dir() else out
    before = inside.read_bytes()
    line = refused(capsys, base_args(command, d, out))
    assert str(inside) in line and "exists (use --force to overwrite it)" in line, line
    assert inside.read_bytes() == before
    if command != "compare":   # compare's work takes long; its --force: tests/test_compare.py
        assert cli.main([str(a) for a in base_args(command, d, out)] + ["--force"]) == 0
        assert inside.read_bytes() != before


def test_reduce_force_replaces_a_summary_only(files, tmp_path, capsys):
    """--force never replaces a catalog or a config, only a reduction summary (issue 26, item 7's
    guard on the analysis side)."""
    for name in ("cat.h5", "cfg.toml"):
        victim = shutil.copy(files / name, tmp_path / ("victim-" + name))
        before = victim.read_bytes()
        line = refused(capsys, ["reduce", files / "cat.h5", "-o", victim, "--force"])
        assert "--force replaces only a reduction summary" in line and str(victim) in line
        assert victim.read_bytes() == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only folder: the refusal cannot be seen")
@pytest.mark.parametrize("command", WRITERS)
def test_an_unwritable_folder_is_refused(files, tmp_path, capsys, command):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        line = refused(capsys, base_args(command, files, locked / "out"))
        assert f"cannot write in {locked}" in line
    finally:
        locked.chmod(0o755)


@pytest.mark.parametrize("command,out", [("reduce", "missing_dir/x.h5"), ("plot", "missing_dir/x.png"),
                                         ("reduce", os.fsdecode(b"x\xff.h5"))])
def test_bad_output_paths_through_the_command_line(files, tmp_path, command, out):
    """As a user types them (issue 27: `-o missing_dir/x.h5` names the folder; issue 26, item 10)."""
    args = [str(a) for a in base_args(command, files, tmp_path / out)]
    res = run_bounded([sys.executable, "-m", "analysis", *args], 120, env=ENV, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), res.stderr
    if "missing_dir" in out:
        assert f"directory {tmp_path / 'missing_dir'} does not exist" in lines[0]
    else:
        assert "is not valid UTF-8" in lines[0] and "x\\xff.h5" in lines[0]
    assert os.listdir(tmp_path) == []
