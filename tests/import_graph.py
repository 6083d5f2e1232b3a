"""The project's imports, read from the sources (ast; nothing is imported, so reading them takes well under a
second). Every import counts, one inside a function included (one placed there to dodge a circle is still one),
and relative ones are resolved. tests/test_imports.py looks for circles in the graph, tests/test_layers.py for
imports across the layers."""
import ast
import functools
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("ensemble", "analysis")


def modules(root=ROOT):
    """{dotted name: path} of every module of the packages (a package is its __init__.py)."""
    out = {}
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            parts = path.relative_to(root).with_suffix("").parts
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def targets(name, path):
    """Everything module `name` (at `path`) imports, anywhere in it, as absolute dotted names: `import a.b` gives
    a.b, `from a import b` gives a.b (b a module of a, or a name defined in a: resolve tells)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                base = ".".join(base + ([node.module] if node.module else []))
            else:
                base = node.module
            found.update(f"{base}.{alias.name}" for alias in node.names)
    return found


def resolve(target, known):
    """The project's module that an import target is (`a.b.c` where only a.b is ours, or a name in a module:
    that module), or '' for another package's."""
    while target and target not in known:
        target = target.rpartition(".")[0]
    return target


def imports(name, path, known):
    """The project's modules that module `name` (at `path`) imports, anywhere in it."""
    return {module for module in (resolve(t, known) for t in targets(name, path)) if module and module != name}


@functools.cache
def graph(root=ROOT):
    """{module: the project's modules it imports} (read once per session)."""
    known = modules(root)
    return {name: imports(name, path, known) for name, path in known.items()}


@functools.cache
def libraries(root=ROOT):
    """{module: the top-level names of the other packages it imports (numpy, os, h5py, ...)}."""
    known = modules(root)
    return {name: {t.partition(".")[0] for t in targets(name, path) if not resolve(t, known)}
            for name, path in known.items()}
