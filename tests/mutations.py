"""Mutation check: would the suite catch the bugs that matter?

Each entry of MUTATIONS is one plausible bug: a file, a piece of its text and what to put
there instead, with the tests that should notice. For each mutation this script copies the
repository (the files git knows, as they are in the working tree) to a scratch directory,
applies the change, runs those tests there and reports whether they failed ("killed") or
passed ("SURVIVED"), and which tier killed it: those of the tests that `make test` runs first,
the slower tier's (marked slow, run by CI) only when those let it pass. A survivor is a hole in
the suite: write the test that kills it.

    python tests/mutations.py                 # all mutations (make mutations); ~40 minutes on 2 cores
    python tests/mutations.py --list          # the list, nothing run
    python tests/mutations.py kernel-free-end-degree reduce-interior-inverted   # some of them

Exit status 0 when every mutation was killed, 1 when one survived or could not be applied
(its text no longer occurs exactly once: the code moved on, update the entry).

Adding a mutation: append a Mutation to MUTATIONS with a unique name, the path relative to
the repository, `old` (text that must occur exactly once in that file, so the entry breaks
loudly when the code changes), `new`, the tests (pytest node ids or files) that should
fail, and `why` (one line: the bug a user would meet). Run it alone by its name and see it
killed. Kernel code is compiled by numba, whose cache does not notice a change in another
module: mutations under ensemble/model/ run with an empty cache (a few minutes of compiling
each), the others share one: a copy of this checkout's, warmed further by the baseline.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT = 1800          # seconds per mutation; a hang counts as killed (the suite's own timeouts fail it first)


@dataclass(frozen=True)
class Mutation:
    name: str
    path: str
    old: str
    new: str
    tests: tuple
    why: str


MUTATIONS = (
    # -- kernel: the event ------------------------------------------------------------------
    Mutation("kernel-free-end-degree", "ensemble/model/geometry/chain.py",
             "return 1.0 + g.l2 * ((1.0 if i > 0 else 0.0) + (1.0 if i < n - 1 else 0.0))", "return 1.0 + g.l2 * 2.0",
             ("tests/test_sequences.py",),
             "free ends treated as interior blocks in the force update after an event"),
    Mutation("kernel-mirror-right-end", "ensemble/model/geometry/chain.py",
             "return i + 1 if i < n - 1 else i\n", "return i + 1 if i < n - 1 else i - 1\n",
             ("tests/test_physics.py", "tests/test_sequences.py"),
             "a mirror neighbour (u_{N} = u_{N-2}) at the right end instead of a free end"),
    Mutation("lattice-no-neighbour-across", "ensemble/model/geometry/lattice.py",
             "return i + g.nx if i + g.nx < n else i\n", "return i\n",
             ("tests/test_plane.py",),
             "a block of the plane without its neighbour across strike (upward): springs missing in every row"),
    Mutation("lattice-edge-stiffness", "ensemble/model/geometry/lattice.py",
             "across = (1.0 if i >= g.nx else 0.0) + (1.0 if i + g.nx < n else 0.0)", "across = 2.0",
             ("tests/test_plane.py",),
             "the blocks on the plane's edges along strike as stiff as interior ones (a wrong edge stiffness)"),
    Mutation("lattice-creep-across-spring", "ensemble/model/geometry/lattice.py",
             "+ g.l2 * (du_l + du_r) + g.l2y * (du_d + du_u)", "+ g.l2 * (du_l + du_r) + g.l2 * (du_d + du_u)",
             ("tests/test_plane.py",),
             "a creeping block of the plane pulled by its creeping neighbours across strike with the spring along"),
    Mutation("graph-spring-to-block-0-missing", "ensemble/model/geometry/graph.py",
             "        if j != i:\n            force += coupling(g, i, j) * (W[j, col] - y)",
             "        if j != i and j != 0:\n            force += coupling(g, i, j) * (W[j, col] - y)",
             ("tests/test_third_geometry.py",),
             "a geometry built on graph.py loses one spring in its forces (a block's neighbour missing)"),
    Mutation("kernel-energy-no-loading-work", "ensemble/model/event.py",
             "e_change += -nu * tau * slip + nu * slip_time", "e_change += -nu * tau * slip",
             ("tests/test_physics.py::test_energy_balance_per_event",),
             "the loading work dropped from the energy balance"),
    Mutation("kernel-no-healing-at-rest-in-event", "ensemble/model/event.py",
             "W[i, P] = rest_state(p.law, W[i, P], tau - W[i, TR])",
             "W[i, P] = W[i, P]",
             ("tests/test_sequences.py", "tests/test_physics.py"),
             "a block that stopped during an event does not heal (theta frozen) until the event ends"),
    Mutation("kernel-aging-law-half-velocity", "ensemble/model/laws/aging.py",
             "return math.exp(-psi) - vp", "return math.exp(-psi) - 0.5 * vp",
             ("tests/test_physics.py", "tests/test_sequences.py"),
             "the state equation theta' = 1 - v theta with a wrong velocity factor"),
    Mutation("kernel-stick-not-located", "ensemble/model/event.py",
             "if W[i, V] <= 0.0 and W[i, V0] > 0.0:", "if W[i, V] < -1e300 and W[i, V0] > 0.0:",
             ("tests/test_convergence.py",),
             "sticking by clamping v at the end of a step instead of cutting the step at v = 0"),
    Mutation("kernel-rk4-weight", "ensemble/model/steppers.py",
             "frac, weight = 0.5, 2.0", "frac, weight = 0.5, 2.05",
             ("tests/test_convergence.py", "tests/test_physics.py"),
             "a wrong weight in the classical RK4 stages"),
    # -- kernel: loading between events and the schedule -------------------------------------
    Mutation("onset-late", "ensemble/model/onset.py",
             "return (y - y_theta) * (b / nu)", "return (y - y_theta) * (b / nu) * (1.0 + 1e-6)",
             ("tests/test_onset.py", "tests/test_sequences.py"),
             "the onset of a block at rest reported late by one part in a million"),
    Mutation("schedule-lazy-loading-lost", "ensemble/model/schedule.py",
             "W[i, F0] += p.nu * dt\n", "W[i, F0] += p.nu * dt * (1.0 - 1e-3)\n",
             ("tests/test_schedule.py", "tests/test_sequences.py"),
             "a block brought forward lazily misses part of its loading"),
    Mutation("schedule-no-healing-between-events", "ensemble/model/schedule.py",
             "W[i, P] = rest_state(p.law, W[i, P], dt)", "W[i, P] = W[i, P] + 0.0 * dt",
             ("tests/test_schedule.py", "tests/test_sequences.py"),
             "a block brought forward lazily does not heal (theta frozen between events)"),
    Mutation("schedule-tree-picks-max", "ensemble/model/schedule.py",
             "k = 2 * k + 1 if tree[2 * k + 1] < tree[2 * k] else 2 * k",
             "k = 2 * k + 1 if tree[2 * k + 1] > tree[2 * k] else 2 * k",
             ("tests/test_schedule.py",),
             "the onset tree descends to the latest block instead of the earliest"),
    Mutation("clock-low-part-dropped", "ensemble/model/schedule.py",
             "clock[1] += (clock[0] - (s - bp)) + (dt - bp)", "clock[1] += 0.0",
             ("tests/test_convergence.py::test_clock_offset_does_not_change_events",),
             "the compensated clock loses its low-order part (times at t ~ 1e15 resolve only ~0.1)"),
    # -- runner and catalog -----------------------------------------------------------------
    Mutation("runner-seed-per-point", "ensemble/run/tasks.py",
             "spawn_key=(task.index,)", "spawn_key=(task.point,)",
             ("tests/test_cli.py",),
             "all seeds of a parameter point draw the same initial state"),
    Mutation("runner-boundary-flag", "ensemble/run/trajectory.py",
             "    edge = (first == 0) | (last == model.N - 1)",
             "    edge = (first == 0) & (last == model.N - 1)",
             ("tests/test_cli.py",),
             "an event reaching one end of the chain is recorded as interior"),
    Mutation("runner-paused-checkpoint-not-undone", "ensemble/model/workspace.py",
             "        if self.paused:\n", "        if False:\n",
             ("tests/test_budget.py",),
             "a checkpoint taken while an event is paused stores the half-integrated state"),
    Mutation("paused-event-two-slots-one-place", "ensemble/model/workspace.py",
             "EV_SLIP_TIME = 11   #", "EV_SLIP_TIME = 10   #",
             ("tests/test_budget.py::test_the_event_state_slots_are_one_each_and_contiguous",
              "tests/test_budget.py::test_the_paused_event_is_saved_and_restored_by_name"),
             "two loop variables of a paused event kept in one slot: the friction work comes back as the slip's "
             "integral"),
    Mutation("paused-event-fields-crossed", "ensemble/model/event.py",
             "    event[EV_WORK] = s.work\n    event[EV_SLIP_TIME] = s.slip_time\n",
             "    event[EV_WORK] = s.slip_time\n    event[EV_SLIP_TIME] = s.work\n",
             ("tests/test_budget.py::test_the_paused_event_is_saved_and_restored_by_name",),
             "a paused event resumes with two of its loop variables exchanged"),
    Mutation("stall-count-per-call", "ensemble/model/event.py",
             "    still = s.still     #", "    still = 0     #",
             ("tests/test_budget.py::test_steps_that_stop_advancing_time_end_the_event_over_any_budget",),
             "steps of no length counted afresh at every kernel call: a run's budgets hide a stalled event"),
    Mutation("event-block-stops-where-it-started", "ensemble/model/event.py",
             "started = W[i, TS] == tau", "started = i == who and (kind == ONSET_NEIGHBOUR or kind == ONSET_LOADING)",
             ("tests/test_attacks.py::test_attack_holds[two blocks on their thresholds within rounding do not take "
              "turns at one time for ever]",),
             "a block started at the start of a step cut to no length stops there: two blocks take turns for ever"),
    Mutation("runner-transient-off-by-one", "ensemble/run/worker.py",
             "recording = traj.done >= traj.discarded", "recording = traj.done >= traj.discarded - 1",
             ("tests/test_cli.py::test_the_transient_is_exactly_run_transient_events_whatever_the_kernel_calls",),
             "the last transient event is recorded"),
    Mutation("catalog-oldest-commit-wins", "ensemble/store/layout.py",
             "if best is None or seq > best.seq:", "if best is None or seq < best.seq:",
             ("tests/test_cli.py::test_catalog_schema_and_content",),
             "resume continues from the older of the two checkpoints"),
    Mutation("catalog-one-checkpoint-slot", "ensemble/store/layout.py",
             "slot = 0 if head is None else 1 - head.slot", "slot = 0",
             ("tests/test_faults.py::test_crash_at_each_kind_of_write_of_a_batch_resumes_to_the_uninterrupted_catalog",),
             "every checkpoint overwrites the only valid one, so a crash while writing it loses the task"),
    Mutation("catalog-state-crc-unchecked", "ensemble/store/layout.py",
             "if crc(flat) != head.state_crc:", "if False:",
             ("tests/test_faults.py::test_a_one_byte_flip_fails_resume_and_read_naming_the_task",),
             "a corrupt checkpoint is resumed from without notice"),
    Mutation("catalog-event-crc-unchecked", "ensemble/store/layout.py",
             "if running.combined() != expected:", "if False:",
             ("tests/test_faults.py::test_a_one_byte_flip_fails_resume_and_read_naming_the_task",),
             "corrupt events are read and reduced without notice"),
    # -- reduction --------------------------------------------------------------------------
    Mutation("reduce-interior-inverted", "analysis/statistics/recurrence.py",
             'acc.count("tnu_interior", block[interior], tnu[interior], edges)',
             'acc.count("tnu_interior", block[~interior], tnu[~interior], edges)',
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "the interior recurrence statistics drawn from the events that reach an end"),
    Mutation("reduce-few-seeds-as-units", "analysis/reduce.py",
             "    if len(stack) >= MIN_UNITS:", "    if len(stack) >= 2:",
             ("tests/test_reduction.py",),
             "a point with a few seeds resampled over those seeds (too narrow intervals), not their stretches"),
    Mutation("stats-interval-level", "analysis/stats.py",
             "q = 50 * (1 - level)", "q = 25 * (1 - level)",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "a 97.5% interval reported as 95%"),
    Mutation("recurrence-window-edge", "analysis/recurrence.py",
             "if abs(xj - pending_x[k]) <= window:", "if abs(xj - pending_x[k]) < window:",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "the recurrence window excludes its edge (10 blocks away)"),
    Mutation("reduce-mode-from-interior", "analysis/statistics/recurrence.py",
             "mode = stats.centers(opt.tnu_edges)[np.argmax(tnu)] if tnu.sum() > 0 else np.nan",
             'mode = stats.centers(opt.tnu_edges)[np.argmax(u["tnu_interior"])] if tnu.sum() > 0 else np.nan',
             ("tests/test_reduction.py",),
             "the mode of T nu taken from the interior events' histogram"),
    Mutation("stats-b-value-natural-log", "analysis/stats.py",
             "return LOG10_E / excess if excess > 0 else np.nan", "return 1.0 / excess if excess > 0 else np.nan",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "the Gutenberg-Richter b-value with the natural instead of the decimal logarithm"),
    Mutation("stats-peaks-without-noise-threshold", "analysis/stats.py",
             "PEAK_Z = 3.0 ", "PEAK_Z = 0.5 ",
             ("tests/test_reduction.py",),
             "noise reported as recurrence peaks"),
    Mutation("stats-gr-b-se-without-b-squared", "analysis/stats.py",
             "return math.log(10.0) * b * b * math.sqrt(", "return math.log(10.0) * b * math.sqrt(",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "a wrong standard error of GR b"),
    Mutation("stats-density-not-per-width", "analysis/stats.py",
             "counts / (np.maximum(total, 1) * widths)", "counts / np.maximum(total, 1)",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "R(mu) normalised as a probability per bin instead of a density"),
    # -- several catalogs -------------------------------------------------------------------
    Mutation("merge-units-in-catalog-order", "analysis/merge.py",
             'points.append(({**dict(zip(PARAMS, key)), "law": law, **shape}, rows))',
             'points.append(({**dict(zip(PARAMS, key)), "law": law, **shape}, sorted(rows)))',
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "a pooled point's intervals change with the order in which its catalogs are given"),
    Mutation("merge-bootstrap-by-point-index", "analysis/reduction.py",
             "merge.bootstrap_rng(opt.seed, params)",
             "merge.np.random.default_rng(merge.np.random.SeedSequence(opt.seed, spawn_key=(len(points),)))",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "a point's intervals change with the other points (and catalogs) of the reduction"),
    Mutation("merge-same-trajectory-twice", "analysis/merge.py",
             "if stream == (", "if False and stream == (",
             ("tests/test_reduction.py", "tests/test_analysis.py"),
             "one trajectory in two catalogs counted as two independent seeds"),
    Mutation("merge-partial-accepted", "analysis/merge.py",
             "if partial and not allow_partial:", "if False:",
             ("tests/test_reduction.py::test_unfinished_runs_need_partial_and_say_so",),
             "an unfinished run reduced as if it were complete"),
    # -- getting at the data: descriptions, export ----------------------------------------
    Mutation("catalog-no-descriptions", "ensemble/store/create.py",
             'h5[name].attrs["description"] = description(entry)', "pass",
             ("tests/test_export.py::test_every_dataset_of_a_catalog_and_a_summary_is_described",),
             "h5dump shows a catalog's datasets without saying what they hold"),
    Mutation("catalog-descriptions-on-rank-0-only", "ensemble/store/create.py",
             'h5[name].attrs["description"] = description(entry)',
             'if h5.driver != "mpio" or __import__("mpi4py").MPI.COMM_WORLD.rank == 0:\n'
             '                h5[name].attrs["description"] = description(entry)',
             ("tests/test_export.py::test_the_parallel_writer_describes_every_dataset",),
             "an attribute written by one rank under mpio: the collective creation hangs (2 minutes)"),
    Mutation("catalog-reader-needs-descriptions", "ensemble/store/layout.py",
             'self.state = h5["checkpoint"]["state"]',
             'self.state = h5["checkpoint"]["state"]; [h5[n].attrs["description"] for n in DATASETS]',
             ("tests/test_export.py::test_a_catalog_without_descriptions_still_reads_and_exports",),
             "catalogs written before the descriptions no longer read"),
    Mutation("summary-dataset-undescribed", "analysis/statistics/recurrence.py",
             'extra_datasets={"peaks": ("model length"', 'extra_datasets={"peak": ("model length"',
             ("tests/test_export.py::test_every_dataset_of_a_catalog_and_a_summary_is_described",
              "tests/test_export.py::test_every_column_has_a_unit_and_a_meaning"),
             "a summary dataset (and its exported columns) without a description"),
    Mutation("export-floats-rounded", "analysis/export_csv.py",
             "return col.astype(str).tolist()",
             'return [f"{x:.15g}" if isinstance(x, float) else str(x) for x in col.tolist()]',
             ("tests/test_export.py::test_catalog_csv_round_trips_exactly",
              "tests/test_export.py::test_summary_csv_round_trips_exactly"),
             "CSV floats that do not read back to the stored values"),
    Mutation("export-booleans-as-integers", "analysis/export_csv.py",
             "return col.astype(str).tolist()",
             'return (col.astype(np.int64) if col.dtype.kind == "b" else col).astype(str).tolist()',
             ("tests/test_export.py::test_csv_holds_what_the_api_returns",),
             "the CSV's booleans read back as integers, not as the API's booleans"),
    Mutation("export-text-unquoted", "analysis/export_csv.py",
             """_SPECIAL = (",", '"', "#", "\\r", "\\n")""", """_SPECIAL = ('"', "\\r", "\\n")""",
             ("tests/test_export.py::test_catalog_csv_round_trips_exactly",),
             "an error message with a comma shifts the columns of tasks.csv"),
    Mutation("export-multiline-text", "analysis/export_tables.py",
             'return " ".join(str(text).splitlines())', "return str(text)",
             ("tests/test_export.py::test_api_events_and_tasks_are_the_catalogs",),
             "a text with a newline splits a CSV row in two"),
    Mutation("export-recipe-off-by-one", "analysis/export_csv.py",
             "skip_header={len(lines)}", "skip_header={len(lines) - 1}",
             ("tests/test_export.py::test_catalog_csv_round_trips_exactly",),
             "the first line's numpy recipe takes the last comment line for the column names"),
    Mutation("tables-crc-unchecked", "ensemble/store/layout.py",
             "if self.protected and (stored is None or int(stored) != fixed_digest(self.h5)):",
             "if self.protected and stored is None:",
             ("tests/test_attacks.py",),
             "a flipped byte in a parameter table or the stored config is read as a real point"),
    Mutation("record-crc-unchecked", "ensemble/store/tables.py",
             'if checksummed and row["record_crc"] != record_crc(task, row):', "if False:",
             ("tests/test_attacks.py",),
             "a flipped byte in a task's integrator or provenance goes unnoticed (a resume runs the wrong integrator)"),
    Mutation("reduce-counts-creep-episodes", "analysis/reduce.py",
             'inertial = part["kind"] == schema.KIND_EVENT', 'inertial = part["kind"] >= schema.KIND_EVENT',
             ("tests/test_catalog_creep.py::test_reduce_counts_the_inertial_events_alone",),
             "creep episodes counted as events in R(mu), the recurrences and GR b"),
    Mutation("intervals-cv-population-sd", "analysis/statistics/intervals.py",
             "max(squares - n * mean * mean, 0.0) / (n - 1)", "max(squares - n * mean * mean, 0.0) / n",
             ("tests/test_intervals.py", "tests/test_reduction.py"),
             "the CV of recurrence and inter-event times with the population standard deviation (too small)"),
    Mutation("intervals-gap-from-nothing", "analysis/statistics/intervals.py",
             "first = 0 if np.isfinite(rows.t_before) else 1", "first = 0 if rows.t_before == rows.t_before else 0",
             ("tests/test_intervals.py", "tests/test_reduction.py"),
             "a task's first event counted as closing an inter-event time (a gap from before the catalog)"),
    Mutation("seismicity-forgets-across-chunks", "analysis/statistics/seismicity.py",
             "keep = allT >= allT[-1] - max(abs(edges[0]), abs(edges[-1]))", "keep = allT > np.inf",
             ("tests/test_seismicity.py",),
             "pairs of a mainshock and an event in another chunk of the task lost (the counts depend on --chunk)"),
    Mutation("seismicity-window-cut-ignored", "analysis/statistics/seismicity.py",
             "cover = max(min(b, end) - max(a, start), 0.0)", "cover = b - a",
             ("tests/test_seismicity.py",),
             "a mainshock's window counted whole where the task's start or end cuts it: rates biased low there"),
    Mutation("seismicity-resample-misses-a-region", "analysis/statistics/seismicity.py",
             'return {"seis_pairs": cells, "seis_exposure": cells}',
             'return {"seis_pairs": cells[1:], "seis_exposure": cells}',
             ("tests/test_seismicity.py",),
             "a resample leaves out a cell the numbers read: their intervals come from NaN"),
    Mutation("region-window-closed-at-its-end", "analysis/reduce.py",
             "return (t >= start) & (t < end)", "return (t >= start) & (t <= end)",
             ("tests/test_populations.py::test_a_region_of_two_faults_is_their_rate_weighted_mixture",),
             "the fault that sets the window gives one event more than its span: its rate over-weighted"),
    Mutation("population-faults-share-one-stream", "ensemble/population.py",
             "spawn_key=(fault, POPULATION_STREAM, zlib.crc32(key.encode()))",
             "spawn_key=(POPULATION_STREAM, zlib.crc32(key.encode()))",
             ("tests/test_populations.py::test_a_faults_draws_are_its_own",),
             "every fault of a population draws the same parameters: a population of one fault repeated"),
    Mutation("region-bootstrap-keyed-by-nothing", "analysis/merge.py",
             "spawn_key=regions.bootstrap_key(params[\"region\"])", "spawn_key=(0,)",
             ("tests/test_populations.py::test_a_region_of_many_faults_resamples_faults",),
             "every region resamples with one stream: intervals not reproducible from the region's text"),
    Mutation("seismicity-chain-without-ends", "analysis/statistics/seismicity.py",
             "lo = max(np.floor(x[m] - D) + 1, 0.0)", "lo = np.floor(x[m] - D) + 1",
             ("tests/test_seismicity.py",),
             "blocks beyond the chain's start counted in a mainshock's exposure: rates near the end biased low"),
    Mutation("resume-drops-the-creep-state", "ensemble/run/trajectory.py",
             "checkpoint.since, creep=checkpoint.creep)", "checkpoint.since)",
             ("tests/test_catalog_creep.py::test_resume_with_creep_in_flight_gives_the_uninterrupted_catalog",),
             "a resumed chain forgets which blocks were creeping: the resumed catalog is another trajectory"),
    Mutation("space-unchecked", "ensemble/run/decision.py",
             "_fits(partial, lambda: space.check_fits(partial, estimate_bytes(cfg, tasks)))", "pass",
             ("tests/test_attacks.py",
              "tests/test_faults.py::test_a_full_disk_stops_the_run_with_one_line_and_nothing_lost"),
             "a disk too small under MPI hangs every rank in HDF5's collective calls"),
    # -- the options, declared by the statistics (analysis/options.py) ------------------------
    Mutation("option-given-ignored", "analysis/options.py",
             "            if getattr(args, name, None) is not None}",
             "            if getattr(args, name, None) is not None and o.kind != \"bins\"}",
             ("tests/test_options.py::test_good_numbers_pass_and_are_converted",),
             "a bins option given on the command line is ignored: the summary has the default bins"),
    Mutation("option-default-moved", "analysis/statistics/seismicity.py",
             "Option(\"seis_near\", \"number\", 2.0,", "Option(\"seis_near\", \"number\", 2.5,",
             ("tests/test_summary_identity.py",),
             "a default changed where it is declared: every summary's numbers move with it, silently"),
    Mutation("option-not-stored", "analysis/options.py",
             "if declared(self.command)[name].kind != \"bins\"}",
             "if declared(self.command)[name].kind not in (\"bins\", \"count\")}",
             ("tests/test_summary_identity.py",),
             "a summary without the counts it was reduced with (window, bootstrap, blocks, seed)"),
    Mutation("export-overwrites", "analysis/export.py",
             "checks.output(path, inputs=[source], force=force, what=\"table\")",
             "checks.output(path, inputs=[source], force=True, what=\"table\")",
             ("tests/test_export.py::test_export_refuses_to_overwrite",),
             "an export replaces tables already in the directory without --force"),
    Mutation("export-file-kind-unchecked", "analysis/export.py",
             'filekind.require(path, "catalog", CatalogError, found)\n    return "catalog"',
             '__import__("h5py").File(path, "r").close()\n    return "catalog"',
             ("tests/test_export.py::test_export_of_a_wrong_file_is_one_line",),
             "a config or directory given to export gets HDF5's words instead of what the file is"),
    Mutation("export-not-streamed", "analysis/export_tables.py",
             "for part in cat.task_events(task, chunk):", "for part in cat.task_events(task, 1 << 40):",
             ("tests/test_export.py::test_api_streams_the_catalog_in_verified_chunks",),
             "a catalog exported a whole task at a time, however large"),
    Mutation("export-failure-leaves-files", "analysis/export.py",
             "            if os.path.exists(tmp):\n                os.remove(tmp)", "            pass",
             ("tests/test_export.py::test_an_export_that_fails_at_a_later_table_leaves_nothing",),
             "an export that fails on a corrupt catalog leaves partial files behind"),
    Mutation("export-peak-interval-swapped", "analysis/statistics/recurrence.py",
             '"tnu_lo": peaks[point, rank, 1], "tnu_hi": peaks[point, rank, 2]',
             '"tnu_lo": peaks[point, rank, 2], "tnu_hi": peaks[point, rank, 1]',
             ("tests/test_export.py::test_peaks_table_of_several_peaks_per_point",),
             "the exported peaks' interval ends swapped"),
    Mutation("export-curve-left-out", "analysis/export_tables.py",
             'if f"points/{curve}_density" not in s:',
             'if curve == "tnu_interior" or f"points/{curve}_density" not in s:',
             ("tests/test_export.py::test_every_summary_dataset_per_point_is_exported",),
             "a density of the summary missing from curves.csv"),
    Mutation("export-summary-taken-for-a-catalog", "analysis/export.py",
             'if found[0] == "summary":', "if False:",
             ("tests/test_export.py::test_api_given_the_other_kind_says_so",),
             "asking a summary for a catalog's table says nothing"),
    Mutation("export-pandas-error-unclear", "analysis/export.py",
             "    try:\n        import pandas\n    except ImportError:", "    import pandas\n    if False:",
             ("tests/test_export.py::test_without_pandas_a_dataframe_is_a_clear_error",),
             "frame=True without pandas fails with a bare import error"),
    Mutation("rupture-length-fits-whole-chain", "analysis/statistics/rupture_length.py",
             "return lr_min, min(lr_max, n_blocks - 1)", "return lr_min, min(lr_max, n_blocks)",
             ("tests/test_rupture_statistics.py::test_the_tables_are_the_events_whatever_the_chunks",),
             "ruptures of the whole chain (the chain's size, not the fault's) inside the L_0 fit"),
    Mutation("rupture-length-span-summed", "analysis/statistics/rupture_length.py",
             "correlation_length(n, excess, span / n if n > 0 else 0)", "correlation_length(n, excess, span)",
             ("tests/test_rupture_statistics.py::test_the_tables_are_the_events_whatever_the_chunks",),
             "the fit's range taken as the summed width of every event's range: L_0 of a far wider law"),
    Mutation("rupture-classes-end-ruptures-classified", "analysis/statistics/rupture_classes.py",
             "& (first > 0) & (last < n_blocks - 1)", "& (last < n_blocks)",
             ("tests/test_rupture_statistics.py::test_the_tables_are_the_events_whatever_the_chunks",),
             "ruptures stopped by a chain end (one-sided by the chain) counted as unilateral"),
    Mutation("rupture-classes-own-zone-as-previous", "analysis/statistics/rupture_classes.py",
             "np.concatenate([[-1], np.where(large, np.arange(n), -1)[:-1]])", "np.where(large, np.arange(n), -1)",
             ("tests/test_rupture_statistics.py::test_the_tables_are_the_events_whatever_the_chunks",),
             "a large event's own rupture zone taken for the previous large event's: every one at its own rim"),
    Mutation("slip-scaling-total-slip", "analysis/statistics/slip_scaling.py",
             "mean = rows.ev[\"slip\"] / np.maximum(length, 1)", "mean = rows.ev[\"slip\"]",
             ("tests/test_rupture_statistics.py::test_the_tables_are_the_events_whatever_the_chunks",),
             "an event's total slip taken for its mean slip per block: a mean slip that grows with L_r"),
    Mutation("slip-scaling-ratio-inverted", "analysis/statistics/slip_scaling.py",
             "(s_hi / n_hi) / (s_lo / n_lo)", "(s_lo / n_lo) / (s_hi / n_hi)",
             ("tests/test_rupture_statistics.py::test_the_tables_are_the_events_whatever_the_chunks",),
             "the lower half's mean slip over the upper's: a falling mean slip read as a rising one"),
    Mutation("stress-drop-without-springs", "ensemble/model/geometry/chain.py",
             "return 1.0 + g.l2 * outside", "return 1.0",
             ("tests/test_physics.py::test_stress_drop_is_the_slipped_blocks_mean_force_drop",),
             "an event's stress drop without the springs to the blocks that did not slip (their pull on the rim)"),
    Mutation("stress-drop-counts-unknown", "analysis/statistics/slip_scaling.py",
             "known = ~np.isnan(drop)", "known = np.ones(len(drop), dtype=bool)",
             ("tests/test_reduction.py::test_summary_equals_brute_force",),
             "events without a stress drop (an older catalog's NaN) counted in its means"),
    Mutation("history-end-not-kept", "ensemble/model/event.py",
             "snapshot(arrays, n, na, nt, tau, na == 0)", "snapshot(arrays, n, na, nt, tau, False)",
             ("tests/test_histories.py::test_a_full_buffer_keeps_the_end",),
             "an event history whose buffer filled up loses its end (the final slip profile)"),
    Mutation("history-slip-as-velocity", "ensemble/model/history.py",
             "H[row, H_VALUES + i] = W[i, V]", "H[row, H_VALUES + i] = W[i, Y]",
             ("tests/test_histories.py::test_a_history_is_its_event_from_onset_to_end",),
             "a history's velocities filled with the slips"),
    Mutation("history-ready-drops-its-row", "ensemble/model/chain.py",
             "hctl[HC_READY] = 1.0     # its snapshots are in `history`: the caller copies them (history.py)\n"
             "            return OK, k\n",
             "hctl[HC_READY] = 1.0     # its snapshots are in `history`: the caller copies them (history.py)\n"
             "            return OK, k - 1\n",
             ("tests/test_histories.py::test_recording_changes_no_event",),
             "the call that hands an event's history over loses the event's row: recording changes the catalog"),
    Mutation("history-row-off-by-one", "ensemble/run/trajectory.py",
             "self._history(self.done + k - 1 - self.discarded)", "self._history(self.done + k - self.discarded)",
             ("tests/test_histories.py::test_a_history_is_its_event_from_onset_to_end",),
             "a history attributed to the row after its event's"),
    Mutation("histories-kept-counts-uncommitted", "ensemble/store/histories.py",
             "np.count_nonzero((rows >= 0) & (rows < written))", "np.count_nonzero(rows >= 0)",
             ("tests/test_histories.py::test_a_run_killed_between_a_history_and_its_commit_resumes_to_the_same",),
             "a history written before a kill, its row never committed, read and counted as kept"),
    Mutation("nucleation-widest-counts-touched", "ensemble/model/event.py",
             "    if na > event[EV_N_WIDEST]:\n        event[EV_N_WIDEST] = na\n",
             "    if nt > event[EV_N_WIDEST]:\n        event[EV_N_WIDEST] = nt\n",
             ("tests/test_histories.py::test_the_nucleation_columns_are_where_the_history_says",),
             "the widest sliding zone counted as every block that has slid (the whole rupture, not the nucleation)"),
    Mutation("nucleation-spread-at-the-first-step", "ensemble/model/event.py",
             "if event[EV_T_SPREAD] < 0.0 and nt > event[EV_N_ONSET]:",
             "if event[EV_T_SPREAD] < 0.0 and nt >= event[EV_N_ONSET]:",
             ("tests/test_histories.py::test_the_nucleation_columns_are_where_the_history_says",),
             "the initial phase ended at the first step, whether or not the sliding zone grew"),
    Mutation("nucleation-counts-older-rows", "analysis/statistics/nucleation.py",
             "has = ev[\"n_onset\"] > 0", "has = ev[\"n_onset\"] >= 0",
             ("tests/test_reduction.py::test_summary_equals_brute_force",),
             "events of a catalog without the nucleation columns (n_onset 0) averaged in as zones of 0 blocks"),
    Mutation("creep-ignores-a", "ensemble/model/creep.py",
             "            r = -(force - friction(p.law, v, psi))",
             "            r = -(force - friction(p.law, 0.0, psi))",
             ("tests/test_creep.py::test_with_velocity_strengthening_a_creeping_cluster_follows_the_full_equations",),
             "the creep's force balance without the velocity strengthening a ln(1 + v) (invisible at a = 0)"),
    Mutation("creep-newton-not-balanced", "ensemble/model/creep.py",
             "    if worst >= 0 and not balanced:", "    if worst >= 0:",
             ("tests/test_creep.py::test_a_cluster_nearly_too_soft_creeps_on",),
             "Newton's updates at the rounding of a nearly-too-soft cluster count as a failure: the cluster goes to "
             "an event that slides at its creep velocities until max_duration"),
    Mutation("slow-slip-afterslip-without-neighbours", "analysis/statistics/slow_slip.py",
             '"lo": ev["first"][main] - 1,', '"lo": ev["first"][main],',
             ("tests/test_slow_slip.py::test_the_table_is_the_rows_whatever_the_chunks",),
             "afterslip only where the mainshock slipped, not on the two blocks beside its rupture zone"),
    Mutation("slow-slip-precursor-anywhere", "analysis/statistics/slow_slip.py",
             '          & (first[taken] - 1 <= carry["epicenter"][j]) & (carry["epicenter"][j] <= last[taken] + 1))',
             "          )",
             ("tests/test_slow_slip.py::test_the_table_is_the_rows_whatever_the_chunks",),
             "any creep episode a mainshock took over counts as its precursor, wherever its epicenter"),
    Mutation("slow-slip-silent-any-size", "analysis/statistics/slow_slip.py",
             "silent = (ending == schema.ENDING_STOPPED) & (mu >= rows.opt.mu_c)",
             "silent = ending == schema.ENDING_STOPPED",
             ("tests/test_slow_slip.py::test_the_table_is_the_rows_whatever_the_chunks",),
             "every creep episode that stopped counts as a silent earthquake, however small"),
    Mutation("slow-slip-afterslip-any-time", "analysis/statistics/slow_slip.py",
             "<= rows.opt.afterslip_window)", "<= 1e300)",
             ("tests/test_slow_slip.py::test_the_table_is_the_rows_whatever_the_chunks",),
             "a creep episode next to the last mainshock is its afterslip however long after it began"),
    Mutation("slow-slip-map-one-row", "analysis/statistics/slow_slip.py",
             'y = ys.index(float(s[f"points/{y_key}"][i])) if y_key else 0', "y = 0",
             ("tests/test_slow_slip.py::test_the_map_shows_each_points_numbers_in_its_cell",),
             "the regime map draws every point in its first row"),
    Mutation("successors-share-of-every-bin", "analysis/successors.py",
             'large = stats.centers(s["bins/mu"]) >= s["attrs"]["mu_c"]\n    return',
             'large = stats.centers(s["bins/mu"]) >= -1e300\n    return',
             ("tests/test_successors.py::test_a_class_share_of_large_events_is_its_counts",),
             "a class's share of large events counts every event of the class"),
    Mutation("successors-halves-at-the-top", "analysis/successors.py",
             'upper = large & (c >= (s["attrs"]["mu_c"] + top) / 2)', 'upper = large & (c >= top - 0.1)',
             ("tests/test_successors.py::test_the_widest_zone_against_magnitude_is_the_halves_ratio",),
             "the widest zone of the largest magnitude bin against all others, not of the larger half of the sizes"),
    Mutation("successors-regime-any-onset", "analysis/successors.py",
             'one = [i for i in strong if s["points/numbers/L_sc"][i][0] == 1.0]',
             'one = [i for i in strong if s["points/numbers/L_sc"][i][0] >= 1.0]',
             ("tests/test_successors.py::test_the_regimes_name_a_point_that_breaks_them",),
             "a strong-regime point whose events start from several blocks is counted as starting from one"),
    Mutation("successors-pool-of-one", "analysis/successors.py",
             "for s, name in zip(summaries, names) if holds(s, paper.needs)]",
             "for s, name in zip(summaries, names) if holds(s, paper.needs)][:1]",
             ("tests/test_successors.py::test_slow_slip_counts_are_every_points",),
             "the slow-slip claims read only the first summary that holds their numbers"),
    Mutation("successors-any-law", "analysis/paper.py",
             "if laws[i] == PAPER_LAW and chains[i]", "if chains[i]",
             ("tests/test_successors.py::test_a_point_of_another_law_or_an_older_summary_is_not_read",
              "tests/test_paper.py::test_a_point_of_another_law_is_not_the_papers_model"),
             "a point of another friction law is read as the papers' model (the seed's claims and its successors')"),
    Mutation("creep-hands-over-on-error", "ensemble/model/creep.py",
             "        who = _accelerating(arrays, n, h, inertial)\n        if who >= 0:",
             "        who = _accelerating(arrays, n, h, inertial)\n        if err > 1.0 and who < 0:\n"
             "            who = arrays.crept[0]\n        if who >= 0:",
             ("tests/test_creep.py::test_creep_relaxing_faster_than_inertia_creeps_on",),
             "creep whose error wants steps below the inertial period hands over to an event though it does not "
             "accelerate: the event slides at the creep's velocity until max_duration"),
    Mutation("creep-epicenter-at-the-pivot", "ensemble/model/creep.py",
             "            # no creep: the cluster became too soft where Newton failed\n"
             "            return HANDOVER, used, _leading(arrays, n, p, bad)",
             "            # no creep: the cluster became too soft where Newton failed\n"
             "            return HANDOVER, used, bad",
             ("tests/test_slip_law.py::test_two_blocks_at_the_paper_rate_alternate_without_small_events",),
             "a hand-over where Newton fails starts at the block of the first non-negative pivot (one end of the "
             "cluster), not at its fastest block"),
    Mutation("points-pool-two-laws", "analysis/merge.py",
             "        bits = (law, *(np.float64", "        bits = (\"\", *(np.float64",
             ("tests/test_compare.py::test_two_laws_with_the_same_keys_are_two_points",),
             "a slip-law run and an aging run of equal a, b, c pool into one point"),
    # -- a plane's catalog in the analysis (analysis/geometry.py; docs/design/geometry.md, step 9) ------------------
    Mutation("plane-recurrences-along-strike-only", "analysis/recurrence.py",
             "    one_row = n_blocks <= n_along", "    one_row = True",
             ("tests/test_plane_analysis.py::test_the_recurrence_times_of_a_plane_are_a_plain_scan_of_its_events",),
             "the recurrence window on a plane measured as the chain's |i - j| between block indices"),
    Mutation("plane-seismicity-distance-along-only", "analysis/statistics/seismicity.py",
             "np.sqrt(float(dx * dx + dy * dy))", "np.sqrt(float(dx * dx))",
             ("tests/test_plane_analysis.py::test_the_seismicity_of_a_plane_counts_euclidean_distances_block_by_block",),
             "the seismicity's distances on a plane measured along strike only"),
    Mutation("plane-shapes-pool", "analysis/merge.py",
             "                *geometry.point_key(tasks, g))", "                )",
             ("tests/test_plane_analysis.py::test_planes_of_another_shape_and_a_chain_never_pool",),
             "two planes of another l_across, or a plane and a chain of the same N, l, nu, pool into one point"),
    Mutation("branch-lowers-creeping-blocks", "ensemble/run/branching.py",
             "    force = np.where(creeping(spun), spun.force, lowered)", "    force = lowered",
             ("tests/test_branch.py::test_a_branch_lowers_the_blocks_at_rest_and_keeps_the_creeping_ones_in_balance",),
             "a branch starts creeping blocks out of force balance"),
)


def applied(text, mutation):
    """The file text with the mutation applied; ValueError unless `old` occurs exactly once."""
    count = text.count(mutation.old)
    if count != 1:
        raise ValueError(f"{mutation.name}: its text occurs {count} times in {mutation.path} (update the entry)")
    return text.replace(mutation.old, mutation.new)


def copy_repository(dest):
    """The files git knows (tracked and untracked-but-not-ignored), as in the working tree; a `.git` file
    pointing at this repository's, so that the tests that take older commits' code from git (the identity test,
    the older catalog formats' attacks) find them in the copy."""
    names = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                           cwd=ROOT, check=True, capture_output=True, timeout=60).stdout.split(b"\0")
    for name in filter(None, names):
        src = ROOT / name.decode()
        if src.is_file():
            (dest / name.decode()).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name.decode())
    git_dir = subprocess.run(["git", "rev-parse", "--absolute-git-dir"], cwd=ROOT, check=True, capture_output=True,
                             text=True, timeout=60).stdout.strip()
    (dest / ".git").write_text(f"gitdir: {git_dir}\n")


def run_tests(copy, tests, cache, timeout, marks=None):
    """(outcome, seconds, first failing test or last output line) of pytest on `tests` in `copy`, only those
    selected by the marker expression `marks` when given ("no tests" when it selects none)."""
    env = dict(os.environ, PYTHONPATH=str(copy), NUMBA_CACHE_DIR=str(cache), OMP_NUM_THREADS="1",
               NUMBA_NUM_THREADS="1", PYTHONDONTWRITEBYTECODE="1")
    start = time.monotonic()
    selection = ["-m", marks] if marks else []
    proc = subprocess.Popen([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *selection, *tests],
                            cwd=copy, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, 9)
        proc.communicate()
        return "killed (timeout)", time.monotonic() - start, f"no result within {timeout} s"
    seconds = time.monotonic() - start
    lines = out.strip().splitlines() or [""]
    failed = next((ln.split(" - ")[0] for ln in lines if ln.startswith(("FAILED", "ERROR"))), lines[-1])
    outcome = {0: "SURVIVED", 1: "killed", 5: "no tests"}.get(proc.returncode, f"error (pytest exit {proc.returncode})")
    return outcome, seconds, failed


def run_tiers(copy, tests, cache, timeout):
    """(outcome, seconds, detail) of `tests` tier by tier: `make test`'s (not slow) first, then the slower tier
    only if those did not kill the mutant; a kill's outcome names the tier that made it."""
    outcome, seconds, detail = run_tests(copy, tests, cache, timeout, "not slow")
    if outcome.startswith("killed"):
        return outcome.replace("killed", "killed (make test)", 1), seconds, detail
    outcome, more, detail = run_tests(copy, tests, cache, timeout, "slow")
    if outcome == "killed":
        return "killed (slow tier)", seconds + more, detail
    return ("SURVIVED" if outcome == "no tests" else outcome), seconds + more, detail


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="mutations to run (default: all)")
    parser.add_argument("--list", action="store_true", help="list the mutations and exit")
    parser.add_argument("--timeout", type=float, default=TIMEOUT, help="seconds per mutation")
    args = parser.parse_args(argv)
    known = {m.name: m for m in MUTATIONS}
    unknown = [n for n in args.names if n not in known]
    if unknown:
        parser.error(f"unknown mutation(s): {', '.join(unknown)}")
    chosen = [known[n] for n in args.names] or list(MUTATIONS)
    if args.list:
        for m in chosen:
            print(f"{m.name:38s} {m.path:28s} {m.why}")
        return 0
    texts = {}
    problems = []
    for m in chosen:
        original = texts.setdefault(m.path, (ROOT / m.path).read_text())
        try:
            applied(original, m)
        except ValueError as err:
            problems.append(str(err))
    for p in problems:
        print(f"error: {p}", file=sys.stderr)
    chosen = [m for m in chosen if not any(p.startswith(m.name + ":") for p in problems)]
    with tempfile.TemporaryDirectory(prefix="bk-mutants-") as scratch:
        scratch = Path(scratch)
        copy = scratch / "repo"
        copy_repository(copy)
        shared = scratch / "cache"
        warm = ROOT / ".numba_cache"     # this checkout's kernels: the unmutated sources' are found by their hash
        if warm.is_dir():
            shutil.copytree(warm, shared, ignore=shutil.ignore_patterns("reference-*"))
        baseline = sorted({t for m in chosen for t in m.tests if (copy / t.split("::")[0]).exists()})
        print(f"baseline: {len(baseline)} test files/ids unmutated", flush=True)
        outcome, seconds, detail = run_tests(copy, baseline, shared, args.timeout * 2)
        if outcome != "SURVIVED":
            print(f"error: the unmutated tests do not pass ({outcome}: {detail}); fix them first", file=sys.stderr)
            return 1
        print(f"baseline passed in {seconds:.0f} s", flush=True)
        results = []
        for m in chosen:
            target = copy / m.path
            missing = [t for t in m.tests if not (copy / t.split("::")[0]).exists()]
            if missing:
                results.append((m, "error (missing tests)", 0.0, ", ".join(missing)))
                print(f"{m.name:38s} {results[-1][1]:18s}          {results[-1][3]}", flush=True)
                continue
            target.write_text(applied(texts[m.path], m))
            cache = scratch / f"cache-{m.name}" if m.path.startswith("ensemble/model/") else shared
            try:
                outcome, seconds, detail = run_tiers(copy, m.tests, cache, args.timeout)
            finally:
                shutil.copy2(ROOT / m.path, target)   # the original text and time stamp
                if cache != shared:
                    shutil.rmtree(cache, ignore_errors=True)
            results.append((m, outcome, seconds, detail))
            print(f"{m.name:38s} {outcome:20s} {seconds:6.0f} s  {detail}", flush=True)
    survivors = [r for r in results if not r[1].startswith("killed")]
    by_tier = {t: sum(r[1] == f"killed ({t})" for r in results) for t in ("make test", "slow tier")}
    print(f"\n{len(results) - len(survivors)} of {len(results)} mutations killed"
          + f" ({by_tier['make test']} by make test, {by_tier['slow tier']} only by the slower tier)"
          + (f"; not killed: {', '.join(r[0].name for r in survivors)}" if survivors else ""))
    return 0 if not survivors and not problems else 1


if __name__ == "__main__":
    sys.exit(main())
