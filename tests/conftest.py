import faulthandler
import os
import sys

import numpy as np
import pytest

from ensemble.store import reader, writers
from ensemble.store.errors import CatalogError
from ensemble.store.files import partial_path
from ensemble.config import Integrator, Model
from ensemble.events import advance_to_onset, check, run_event
from ensemble.integrators import kernel_params
from ensemble.model.chain import simulate
from ensemble.model.workspace import NDIAG, UNLIMITED, Workspace

from .processes import ROOT, child_env, run_bounded  # noqa: F401 (ROOT: test modules import it from here)

# -- a backstop behind the per-test timeout ----------------------------------------------------
# pytest-timeout (setup.cfg: `timeout`, method "signal") fails a test that runs too long and the
# session goes on; the test's `finally` blocks kill what it started. Its SIGALRM is served between
# bytecodes, though, and so is the thread method's timer thread (it needs the GIL): a numba kernel
# looping for ever in this process holds the GIL and is out of reach of both. faulthandler's
# watchdog is a C thread: BACKSTOP_SECONDS after the test's own limit it prints the stack of every
# thread and ends the session (exit 1).
BACKSTOP_SECONDS = 120
_STDERR = pytest.StashKey[int]()

# As in an activated .venv: the wheel stack's mpiexec (the mpich wheel) is the one beside python.
os.environ["PATH"] = os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", "")


# -- the quick tier (`make quick`, `pytest -m quick`) -------------------------------------------
# About a minute here (docs/tests.md) that touch every module of ensemble/ and analysis/: the
# cheapest test, or few, of each layer (one case of a parametrized test: "test_x[its id]"). Named here
# rather than marked in each file, so that the tier is one list to read. tests/test_quick_tier.py checks
# that every name exists and that every test file is here or in NOT_QUICK, with the reason.
QUICK = {
    "test_plane_study.py": ["test_an_epicenter_on_the_rim_against_its_share_of_the_zone"],
    "test_example_configs.py": ["test_the_examples_hold_configs", "test_an_example_config_loads"],
    "test_creep.py": ["test_a_cluster_too_soft_to_creep_hands_over_to_an_event",
                      "test_above_the_block_stiffness_nothing_creeps"],
    "test_intervals.py": ["test_every_statistic_is_the_same_whatever_the_chunks"],
    "test_seismicity.py": ["test_a_hand_built_chain_gives_its_known_counts_and_exposures"],
    "test_new_statistic.py": ["test_a_statistic_is_one_file"],
    "test_statistic_contract.py": ["test_every_statistic_touches_only_what_it_declares"],
    "test_summary_identity.py": ["test_a_reduction_gives_the_committed_summary"],
    "test_slip_law.py": ["test_two_blocks_at_the_paper_rate_alternate_without_small_events"],
    "test_creep_reference.py": ["test_quasi_static_creep_is_stable_exactly_while_its_matrix_is_positive_definite"],
    "test_install.py": ["test_an_unknown_stack_is_an_error_naming_it", "test_a_module_system_prefix_in_hdf5_dir",
                        "test_every_entry_point_takes_the_packages_kernel_cache"],
    "test_onset.py": ["test_lambert_root_on_upper_branch", "test_onset_delay_matches_brute_force",
                      "test_fast_forward_lands_on_threshold_of_epicenter_only"],
    "test_physics.py": ["test_single_block_instability_threshold"],
    "test_ark4.py": ["test_tableau_order_conditions", "test_kernel_arrays_are_the_tableau",
                     "test_zero_step_keeps_the_state[ark4]"],
    "test_schedule.py": ["test_tree_finds_the_smallest_key_after_any_updates"],
    "test_budget.py": ["test_between_events_state_of_a_paused_event[b = 20-ark4]"],
    "test_catalog_creep.py": ["test_a_checkpoint_packs_its_creep_state_and_a_slot_of_another_size_is_refused"],
    "test_laws.py": ["test_a_key_of_another_law_is_an_error_naming_it",
                     "test_single_block_slip_is_the_linearised_oscillation"],
    "test_nonfinite.py": ["test_tree_min_returns_a_block_whatever_the_keys"],
    "test_cli.py": ["test_validate_prints_resolved_config_and_tasks",
                    "test_bad_config_gives_one_line_error_naming_the_key",
                    "test_catalog_schema_and_content", "test_status_summarises_a_finished_catalog"],
    "test_input_errors.py": ["test_identify", "test_load_says_what_a_non_config_is",
                             "test_run_guarded_codes_and_messages",
                             "test_closed_pipe_exits_141_without_traceback"],
    "test_faults.py": ["test_output_paths_are_checked_before_any_work", "test_a_stale_lock_of_a_dead_run_is_taken_over",
                       "test_a_one_byte_flip_fails_resume_and_read_naming_the_task[event-fail their checksum]"],
    "test_mpi.py": ["test_a_genuine_error_on_one_rank_aborts_the_job"],
    "test_branch.py": ["test_branch_keys_are_validated_by_name"],
    "test_analysis.py": ["test_recurrence_scan_matches_brute_force", "test_b_value_recovers_known_gutenberg_richter"],
    "test_reduction.py": ["test_percentile_interval_leaves_the_documented_share_outside",
                          "test_peak_finder_follows_its_documented_rule"],
    "test_figures.py": ["test_synthetic_figures_cover_no_data[4-high right half]"],
    "test_creep_statistics.py": ["test_a_summary_of_format_2_reads_reports_exports_without_creep"],
    "test_paper.py": ["test_bad_input_is_one_line_naming_the_file"],
    "test_compare.py": ["test_power_law_fit_recovers_the_exponent",
                        "test_dip_is_one_without_a_hump_and_the_ratio_with_one"],
    "test_paper_docs.py": ["test_readme_claims_table_is_the_generated_one",
                           "test_tables_md_is_what_the_summaries_give"],
    "test_convergence.py": ["test_clock_offset_does_not_change_events"],
    "test_ark3.py": ["test_run_with_ark3"],
    "test_exp4.py": ["test_the_new_state_is_exact_for_a_remainder_of_degree_2_at_any_z",
                     "test_a_law_with_a_state_not_linear_in_theta_is_refused_naming_the_keys",
                     "test_a_config_without_a_method_takes_its_laws"],
    "test_processes.py": ["test_wait_for_fails_when_the_command_ends_first_or_time_runs_out",
                          "test_the_ranks_of_mpiexec_are_killed_too"],
    "test_slurm.py": ["test_time_limits_as_slurm_reads_them", "test_rendered_scripts_are_complete_and_valid_bash",
                      "test_cli_renders_without_submitting"],
    "test_benchmarks.py": ["test_distances_agree_with_scipy", "test_settings_are_validated"],
    "test_time_to_statistics.py": ["test_schedule_replays_the_counter"],
    "test_options.py": ["test_every_numeric_option_is_checked_and_attacked",
                        "test_huge_bins_are_refused_before_any_file_is_read"],
    "test_imports.py": ["test_no_module_imports_itself_round_a_circle",
                        "test_the_graph_sees_imports_inside_functions_and_relative_ones",
                        "test_the_store_modules_are_small"],
    "test_compare_engine.py": ["test_the_engines_tables_of_the_comparison_are_the_events"],
    "test_integrator_keys.py": ["test_the_config_section_is_the_declaration",
                                "test_each_key_reaches_the_kernels_by_name"],
    "test_populations.py": ["test_a_faults_draws_are_its_own", "test_bad_population_specs_are_errors_naming_the_key",
                            "test_a_region_of_two_faults_is_their_rate_weighted_mixture"],
    "test_layers.py": ["test_the_kernels_import_only_each_other_numpy_numba_and_the_standard_library",
                       "test_the_store_does_not_import_the_run",
                       "test_analysis_imports_of_the_run_only_the_abort_guard", "test_every_rule_fails_when_broken"],
    "test_compiled.py": ["test_a_compilation_is_said_in_one_line_with_its_time_and_its_end",
                         "test_compile_refuses_a_bad_argument_in_one_line"],
    "test_mutation_targets.py": ["test_every_mutant_applies_once_and_names_existing_tests"],
    "test_quick_tier.py": ["test_every_test_named_in_the_quick_tier_exists",
                           "test_every_test_file_is_in_the_quick_tier_or_says_why_not"],
    "test_writes.py": ["test_no_module_writes_a_file_around_the_helper"],
    "test_api.py": ["test_a_config_is_a_path_a_toml_text_or_a_dict"],
    "test_rupture_statistics.py": ["test_the_tables_are_the_events_whatever_the_chunks",
                                   "test_the_correlation_length_recovers_the_scale_of_exponential_draws",
                                   "test_a_hand_built_sequence_gives_its_classes"],
    "test_slow_slip.py": ["test_the_table_is_the_rows_whatever_the_chunks"],
    "test_successors.py": ["test_the_regimes_name_a_point_that_breaks_them"],
    "test_plane_analysis.py": ["test_the_scanner_on_a_plane_is_a_plain_scan_whatever_the_chunks",
                               "test_the_seismicity_of_a_plane_counts_euclidean_distances_block_by_block"],
}
NOT_QUICK = {   # test files with no test in the quick tier, and why
    "test_sequences.py": "every test needs a serial catalog and a full-chain reference (10 s and more)",
    "test_hard_cases.py": "hard cases at their own sizes (N = 6400, t = 1e15): tens of seconds each",
    "test_kernel_identity.py": "compiles the kernels of a reference commit first (about 15 s, more under load)",
    "test_third_law.py": "compiles a copy of the package with a third law (about a minute)",
    "test_new_integrator.py": "compiles a copy of the package with a sixth integrator (about a minute and a half)",
    "test_export.py": "every test reads the module's catalog and summary (8 s to make); export is in the quick tier "
                      "through test_creep_statistics.py",
    "test_attacks.py": "every attack starts from a catalog of its own (7 s and more); the quick tier's flipped byte "
                       "is test_faults.py's",
    "test_histories.py": "every test reads catalogs of real runs with and without histories (about 20 s to make)",
    "test_plane.py": "every test runs a plane: a plain full-lattice integration, runs on two ranks and a killed one "
                     "(about 30 s in all)",
    "test_third_geometry.py": "compiles a copy of the package with a third geometry (about a minute)",
}


def pytest_configure(config):
    config.addinivalue_line("markers", "quick: the quick tier, `make quick` (tests/conftest.py QUICK, docs/tests.md)")
    # stderr itself, kept for the watchdog: during a test fd 2 is pytest's capture file
    config.stash[_STDERR] = os.dup(sys.stderr.fileno())
    # `make test` sets up the parallel stack and says so: then no test may skip for want of MPI-IO
    if os.environ.get("ENSEMBLE_TEST_STACK") == "parallel" and not writers.has_parallel_hdf5():
        raise pytest.UsageError("ENSEMBLE_TEST_STACK=parallel, but this h5py has no MPI support "
                                "(rerun `make test`, or `make test STACK=wheels` to skip the MPI-IO tests)")


# The files that take longest (2026-11-29: the slower tier's two, then `make test`'s), run first: with the Makefile's
# --dist loadfile --no-loadscope-reorder the workers take files in this order, so the long ones do not end the run
# on one worker while the other idles. Only the order of the run; a stale list costs time, never a result.
LONGEST_FIRST = ("test_slurm.py", "test_compiled.py", "test_attacks.py", "test_mpi.py", "test_faults.py",
                 "test_reduction.py", "test_input_errors.py", "test_catalog_creep.py", "test_budget.py",
                 "test_hard_cases.py", "test_branch.py", "test_populations.py", "test_figures.py", "test_laws.py",
                 "test_cli.py", "test_export.py")


def pytest_collection_modifyitems(config, items):
    rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))     # stable: the rest as collected
    for item in items:      # a name in QUICK is every case of a test, or one case: "test_x[its id]"
        if {item.name, item.originalname} & set(QUICK.get(item.path.name, ())):
            item.add_marker(pytest.mark.quick)
    if writers.has_parallel_hdf5():
        return
    skip = pytest.mark.skip(reason="h5py without MPI (the wheel stack): the parallel writer is not "
                                   "tested here; `make test` sets up the parallel stack and tests it")
    for item in items:
        if item.get_closest_marker("parallel_hdf5"):
            item.add_marker(skip)


# the attacks' outcomes in this run (tests/test_attacks.py), for the table at its end: test id -> (outcome, seconds)
_ATTACKS = {}
_ATTACK_TEST = "test_attacks.py::test_attack_holds["
_OUTCOME = {"passed": "held", "skipped": "skipped", "failed": "FAILED"}


def pytest_runtest_logreport(report):
    """Each attack's outcome (with xdist, the workers' reports reach this process too)."""
    if _ATTACK_TEST in report.nodeid and (report.when == "call" or report.outcome != "passed"):
        seconds = _ATTACKS.get(report.nodeid, ("", 0.0))[1] + report.duration
        if report.nodeid not in _ATTACKS or report.outcome != "passed":
            _ATTACKS[report.nodeid] = (_OUTCOME[report.outcome], seconds)


def pytest_terminal_summary(terminalreporter):
    """The attacks' table, as `python tests/attack.py` prints it, when the run had attacks (CI's log shows it)."""
    if not _ATTACKS:
        return
    from tests.attack import table
    rows = [(nodeid.split("[", 1)[1][:-1], outcome, seconds) for nodeid, (outcome, seconds) in _ATTACKS.items()]
    terminalreporter.section("the attacks at the edges (tests/attack.py)")
    for line in table(rows):
        terminalreporter.write_line(line)


def pytest_unconfigure(config):
    os.close(config.stash[_STDERR])


def timeout_of(item):
    """The timeout pytest-timeout applies to `item` (marker > --timeout > PYTEST_TIMEOUT > ini), 0 for none."""
    mark = item.get_closest_marker("timeout")
    if mark is not None:
        value = mark.args[0] if mark.args else mark.kwargs.get("timeout")
    else:
        value = item.config.getoption("timeout", None) or os.environ.get("PYTEST_TIMEOUT")
        if value is None:
            try:
                value = item.config.getini("timeout")
            except ValueError:      # pytest-timeout is not installed
                value = None
    return float(value or 0)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item, nextitem):
    limit = timeout_of(item)
    if limit > 0:
        faulthandler.dump_traceback_later(limit + BACKSTOP_SECONDS, exit=True, file=item.config.stash[_STDERR])
    try:
        return (yield)
    finally:
        if limit > 0:
            faulthandler.cancel_dump_traceback_later()


def developed_state(model, events, seed=1, dt=1e-3):
    """(force, psi) of a chain after `events` events from a random start."""
    rng = np.random.default_rng(seed)
    ws = Workspace(model.N)
    ws.load(-rng.random(model.N), np.zeros(model.N))
    clock = np.zeros(2)
    t = np.empty(events)
    epi = np.empty(events, dtype=np.int64)
    diag = np.empty((events, NDIAG))
    params = kernel_params(model, Integrator(method="rk4", dt=dt))
    status, k = simulate(ws.arrays, clock, params, events, UNLIMITED, t, epi, diag)
    assert status == 0
    return ws.state(clock, params)


def next_event(force, psi, model, dt, v_start=0.0):
    """Jump to the next onset and integrate that event with fixed-step RK4 at dt."""
    epicenter, _, f, p = advance_to_onset(force, psi, model)
    f[epicenter] = model.b * p[epicenter]
    return epicenter, check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=dt), v_start))


def run_cli(*args, cwd=None, timeout=600):
    """`python -m ensemble ARGS` in a subprocess; a hang fails the test, showing the output."""
    return run_bounded([sys.executable, "-m", "ensemble", *args], timeout, cwd=cwd, env=child_env())


def committed(out):
    """True once the run writing catalog `out` has committed a batch of events (readable, not yet renamed)."""
    try:
        _, tasks, _ = reader.read_tasks(partial_path(out))
    except CatalogError:
        return False      # not created yet, or open for writing at that moment
    return tasks["events_written"].sum() > 0


def write_config(path, **sections):
    """A small config file: sections given as dicts override the test defaults (a value None drops the key)."""
    # no integrator key: the law's own method (the aging law's exp4 takes about a fifth of the time of rk4 at
    # dt = 1e-3 for these runs); a test that needs rk4's fixed steps, or long events, says so in `integrator`
    base = {"model": {"N": 60, "b": 20.0}, "run": {"events": 40, "transient": 20, "seeds": 2},
            "integrator": {}, "output": {"path": str(path.with_suffix(".h5"))}}
    for name, values in sections.items():
        base.setdefault(name, {}).update(values)
    lines = []
    for name, values in base.items():
        lines.append(f"[{name}]")
        for k, v in values.items():
            if v is None:
                continue
            if isinstance(v, bool):
                lines.append(f"{k} = {'true' if v else 'false'}")
            elif isinstance(v, str):
                lines.append(f'{k} = "{v}"')
            elif isinstance(v, list):
                lines.append(f"{k} = {v!r}")
            else:
                lines.append(f"{k} = {v!r}")
        lines.append("")
    path.write_text("\n".join(lines))
    return path


@pytest.fixture(scope="session")
def events():
    """Pre-event states of the next few events of a developed chain, and RK4 references (once per session, or
    per pytest worker: 200 events of RK4 at dt = 1e-3 take about 5 s; the tests read them, none changes them)."""
    model = Model(N=100, b=20.0, a=2.0)
    force, psi = developed_state(model, 200)
    out = []
    for _ in range(4):
        epicenter, _, f, p = advance_to_onset(force, psi, model)
        f[epicenter] = model.b * p[epicenter]
        ref = check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=1.25e-4)))
        out.append((f, p, epicenter, ref))
        force, psi = ref.force, ref.psi
    return model, out
