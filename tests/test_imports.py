"""The project's import graph (read from the sources: tests/import_graph.py): no circle among its modules, and the
packages' modules small.
"""
from .import_graph import ROOT, graph

MODULE_LINES = 400      # lines at most of a module of the packages below (one job each)
SMALL_PACKAGES = ("ensemble/store", "ensemble/run", "ensemble/slurm")


def cycles(edges):
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def test_no_module_imports_itself_round_a_circle():
    found = cycles(graph())
    assert found == [], "import circles: " + "; ".join(" <-> ".join(c) for c in found)


def test_the_graph_sees_imports_inside_functions_and_relative_ones():
    edges = graph()
    assert "ensemble.model.creep" in edges["ensemble.store.checkpoint"]     # (inside carries_creep)
    assert "ensemble.store.schema" in edges["ensemble.store.layout"]         # from .schema import ...
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_the_store_modules_are_small():
    sizes = {path.name: len(path.read_text().splitlines()) for path in (ROOT / "ensemble" / "store").glob("*.py")}
    assert {"schema.py", "layout.py", "reader.py", "writers.py"} <= set(sizes)
    assert {name: n for name, n in sizes.items() if n > MODULE_LINES} == {}


def test_the_run_and_slurm_modules_are_small():
    sizes = {str(path.relative_to(ROOT)): len(path.read_text().splitlines())
             for package in SMALL_PACKAGES for path in (ROOT / package).glob("*.py")}
    assert {"ensemble/run/runner.py", "ensemble/run/worker.py", "ensemble/run/context.py",
            "ensemble/slurm/render.py"} <= set(sizes)
    assert {name: n for name, n in sizes.items() if n > MODULE_LINES} == {}


def test_the_run_is_no_flat_module_any_more():
    """The run's modules live in ensemble/run/ only: a module left (or put back) beside it would be a
    second place to change."""
    flat = {"runner", "tasks", "branching", "parallel", "lock", "abort", "status", "slurm"}
    assert {p.stem for p in (ROOT / "ensemble").glob("*.py")} & flat == set()
