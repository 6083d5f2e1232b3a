"""The layers drawn in docs/code_map.md, kept by reading the imports (tests/import_graph.py: every import, one
inside a function included, nothing imported). An import through another module counts: a layer that may not
import X may not import a module that imports X either.

- The kernels (ensemble/model/) see no config, file or MPI: they import only each other, numpy, numba and the
  standard library, and ensemble.kernel_cache (KERNEL_NEIGHBOURS, with the reason).
- The store (ensemble/store/) does not call the run (ensemble/run/): what both need, the task list a config asks
  for, is ensemble/sweep.py.
- The analysis (analysis/) reads catalogs through the store and takes of the run only its entry points' guard
  (ANALYSIS_RUN_MODULES).

Each rule is a function returning what breaks it; test_every_rule_fails_when_broken breaks each once.
"""
import sys

from .import_graph import graph, libraries

MODEL = "ensemble.model"
STORE = "ensemble.store"
RUN = "ensemble.run"
ANALYSIS = "analysis"
KERNEL_LIBRARIES = {"numpy", "numba"}
# model/__init__.py keys numba's cache directory with kernel_cache.directory(): a module of the standard library
# alone (hashlib, os, pathlib) that reads no config, opens no catalog and knows no MPI, kept outside model/ because
# every entry point, scripts/setup.sh and the tests name the same cache through it without importing the kernels
KERNEL_NEIGHBOURS = {"ensemble.kernel_cache"}
# the run's modules that analysis may import: abort.py, the entry points' guard (one rank's exception ends every
# rank; run_guarded, abort_on_error, on_root), which imports only the standard library and is documented for the
# entry points "here and in analysis" (ensemble/run/__init__.py)
ANALYSIS_RUN_MODULES = {"ensemble.run.abort"}


def inside(module, package):
    return module == package or module.startswith(package + ".")


def reached(start, edges):
    """{module: the module it is first imported from} of every module that importing `start` imports
    (start's own map to None)."""
    came_from = {m: None for m in start}
    todo = sorted(start)
    while todo:
        v = todo.pop(0)
        for w in sorted(edges.get(v, ())):
            if w not in came_from:
                came_from[w] = v
                todo.append(w)
    return came_from


def path_to(module, came_from):
    steps = [module]
    while came_from[steps[-1]] is not None:
        steps.append(came_from[steps[-1]])
    return " -> ".join(reversed(steps))


def kernel_problems(edges, libs):
    """What the kernels import beyond themselves, KERNEL_NEIGHBOURS, numpy, numba and the standard library."""
    model = {m for m in edges if inside(m, MODEL)}
    came_from = reached(model, edges)
    out = [f"{path_to(m, came_from)}: the kernels import no module of the project outside ensemble/model/"
           for m in sorted(came_from) if not inside(m, MODEL) and m not in KERNEL_NEIGHBOURS]
    allowed = KERNEL_LIBRARIES | set(sys.stdlib_module_names)
    out += [f"{m} imports {', '.join(sorted(libs[m] - allowed))}: the kernels use numpy, numba and the standard "
            f"library only" for m in sorted(came_from) if m in libs and libs[m] - allowed]
    return out


def store_problems(edges):
    """The run's modules that importing any module of the store imports."""
    came_from = reached({m for m in edges if inside(m, STORE)}, edges)
    return [f"{path_to(m, came_from)}: the store does not import the run" for m in sorted(came_from) if inside(m, RUN)]


def analysis_problems(edges):
    """The run's modules beyond ANALYSIS_RUN_MODULES that importing any module of analysis imports."""
    came_from = reached({m for m in edges if inside(m, ANALYSIS)}, edges)
    return [f"{path_to(m, came_from)}: analysis takes of the run only {', '.join(sorted(ANALYSIS_RUN_MODULES))}"
            for m in sorted(came_from) if inside(m, RUN) and m not in ANALYSIS_RUN_MODULES]


def test_the_kernels_import_only_each_other_numpy_numba_and_the_standard_library():
    assert kernel_problems(graph(), libraries()) == []


def test_the_store_does_not_import_the_run():
    assert store_problems(graph()) == []


def test_analysis_imports_of_the_run_only_the_abort_guard():
    assert analysis_problems(graph()) == []


def test_every_rule_fails_when_broken():
    """One forbidden import added to a copy of the graph, for each rule: directly, and through another module."""
    edges, libs = graph(), libraries()

    def plus(module, target):
        return {**edges, module: edges[module] | {target}}

    assert kernel_problems(plus("ensemble.model.chain", "ensemble.config"), libs)
    assert kernel_problems(plus("ensemble.kernel_cache", "ensemble.run.parallel"), libs)
    assert kernel_problems(edges, {**libs, "ensemble.model.event": libs["ensemble.model.event"] | {"h5py"}})
    assert kernel_problems(edges, {**libs, "ensemble.kernel_cache": {"mpi4py"}})
    assert store_problems(plus("ensemble.store.layout", "ensemble.run.tasks"))
    assert store_problems(plus("ensemble.sweep", "ensemble.run.tasks"))         # through the task list
    assert analysis_problems(plus("analysis.region", "ensemble.run.worker"))
    assert analysis_problems(plus("ensemble.store.reader", "ensemble.run.lock"))  # through the store
    assert analysis_problems(plus("ensemble.run.abort", "ensemble.run.parallel"))  # through the guard itself
