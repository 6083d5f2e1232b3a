"""A reduction's options, built from what the statistics declare (analysis/statistics/: Option).

Each option is declared once, in the statistic that reads it (or, for the resampling, the engine's
ENGINE_OPTIONS); a command that reduces ("reduce", "compare": a set of statistics) has the options its
statistics declare or use, those of the criteria of a large event whose recurrences they need, and the
engine's. From these declarations come, with nothing restated elsewhere:

- the options record (`make`): each option by name, checked (opt.mu_c), a bins option's edges too
  (opt.mu_edges, from "lo:hi:n" or given as edges), the defaults where none was given (a LAW default is
  the friction law's scale, Law.scales);
- the command line's arguments and their checks (`add_arguments`, `check`: one line naming the option,
  before any file is read);
- the summary's stored options (`Options.stored`: the attributes; bins are stored as /bins/<name>) and
  the comparison's (`Options.changed`, its json's `options`).
"""
import numpy as np

from ensemble import checks

from .reduce import MAX_BINS, parse_bins
from .statistics import CRITERIA, ENGINE_OPTIONS, LAW, STATISTICS, of

CHUNK = 1 << 16     # rows a task streams in at a time (not an option: tests set it, Options.chunk)


def declared(command="reduce"):
    """{name: Option} of a command's reduction: what its statistics declare or use (with the options of the
    criteria their recurrences need), in the statistics' order, then the engine's."""
    by_name = {o.name: o for st in STATISTICS for o in st.options}
    names = []
    for st in of(command):
        names += [o.name for o in st.options] + list(st.uses_options)
        for need in st.needs:
            if need.startswith("recurrences"):
                c = CRITERIA[need.partition(":")[2] or "mu"]
                names += [c.threshold, c.window]
    return {**{name: by_name[name] for name in dict.fromkeys(names)}, **{o.name: o for o in ENGINE_OPTIONS}}


def every_option():
    """{name: Option} of every command (one declaration each)."""
    return {name: o for command in ("reduce", "compare") for name, o in declared(command).items()}


def check(option, value):
    """A value given for `option`, checked (checks.UsageError naming its argument otherwise): a float, an int, or
    bins: "lo:hi:n" text (kept as text) or edges (finite, strictly increasing, at most MAX_BINS bins)."""
    if option.kind == "bins":
        if isinstance(value, str):
            parse_bins(value, option.flag)
            return value
        edges = np.asarray(value, dtype=float)
        if edges.ndim != 1 or not 2 <= len(edges) <= MAX_BINS + 1 or not (
                np.all(np.isfinite(edges)) and np.all(np.diff(edges) > 0)):
            raise checks.UsageError(f"{option.flag} must be lo:hi:n or at least two finite increasing edges (at "
                                    f"most {MAX_BINS} bins)")
        return edges
    if option.kind == "count":
        return checks.count(option.flag, value, lo=int(option.low), hi=int(option.high))
    return checks.number(option.flag, value, option.low, option.high, exclusive=option.exclusive)


def default(option, command="reduce", scales=None):
    """The option's default in `command`; a LAW default from `scales` (a friction law's Law.scales), None without."""
    value = option.defaults.get(command, option.default)
    if isinstance(value, str) and value == LAW:
        return None if scales is None else getattr(scales, option.name)
    return value


def help_text(option, command="reduce"):
    """The argument's help: the option's, its unit where it says more than a count, and its default."""
    value = option.defaults.get(command, option.default)
    if isinstance(value, str) and value == LAW:
        from ensemble.model import laws
        value = f"the law's; aging {getattr(laws.get('aging').scales, option.name)}"
    elif option.kind == "number":
        value = f"{value:g}"
    unit = f", {option.unit}" if option.unit not in ("1", "blocks", "") and option.kind != "bins" else ""
    return f"{option.help}{unit} (default {value})"


class Options:
    """A reduction's options: every option of its command by name (opt.mu_c), a bins option's edges as
    <bins>_edges (opt.mu_edges), and `chunk`. Read-only; make() builds it."""

    def __init__(self, command, values, chunk):
        edges = {f"{o.bins}_edges": values[o.name] if not isinstance(values[o.name], str)
                 else parse_bins(values[o.name], o.flag) for o in declared(command).values() if o.kind == "bins"}
        object.__setattr__(self, "_values", dict(values))
        object.__setattr__(self, "_edges", edges)
        object.__setattr__(self, "command", command)
        object.__setattr__(self, "chunk", chunk)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        for table in ("_values", "_edges"):
            found = self.__dict__[table]
            if name in found:
                return found[name]
        raise AttributeError(f"the {self.command} options have no {name!r} (analysis/options.py: declared)")

    def __setattr__(self, name, value):
        raise AttributeError("the options are read-only: make() another")

    def __reduce__(self):
        """For pickle (the ranks of a reduction receive rank 0's): built again from its values."""
        return Options, (self.command, self._values, self.chunk)

    def __repr__(self):
        return f"Options({self.command!r}, {self._values!r})"

    def values(self):
        """{name: value} of every option, in declaration order (bins as given: text or edges)."""
        return dict(self._values)

    def stored(self):
        """{name: value} of the options a summary stores as attributes (all but the bins: /bins/<name>)."""
        return {name: v for name, v in self._values.items() if declared(self.command)[name].kind != "bins"}

    def changed(self):
        """{name: value} of the options given other than their default (a command line that reproduces them)."""
        decl = declared(self.command)
        return {name: v for name, v in self._values.items() if not _same(v, default(decl[name], self.command))}


def _same(a, b):
    """Two values of an option are the same (bins as text or edges: the same text, or equal edges)."""
    if isinstance(a, str) or isinstance(b, str):
        return isinstance(a, str) and isinstance(b, str) and a == b
    return bool(np.array_equal(a, b))


def make(command="reduce", scales=None, chunk=None, **given):
    """The options record of `command` from the values `given` by name (None or absent: the default), each
    checked; a LAW default needs `scales` (a friction law's Law.scales; ValueError naming the option without).
    chunk: rows a task streams in at a time (default CHUNK, read at the call: a test sets it)."""
    decl = declared(command)
    unknown = sorted(set(given) - set(decl))
    if unknown:
        raise checks.UsageError(f"{command} has no option {', '.join(unknown)} (its options: {', '.join(decl)})")
    values = {}
    for name, o in decl.items():
        value = given.get(name)
        if value is None:
            value = default(o, command, scales)
            if value is None:
                raise ValueError(f"{o.flag}: its default is the friction law's; give the value or the law's scales")
        values[name] = check(o, value)
    return Options(command, values, CHUNK if chunk is None else chunk)


def add_arguments(parser, command="reduce"):
    """The command line's argument of every option of `command` (text, checked by check(); None when not given)."""
    for o in declared(command).values():
        parser.add_argument(o.flag, dest=o.name, default=None, help=help_text(o, command))


def given(args, command="reduce"):
    """{name: value} of the options given on the command line (args: argparse's), each checked."""
    return {name: check(o, getattr(args, name)) for name, o in declared(command).items()
            if getattr(args, name, None) is not None}
