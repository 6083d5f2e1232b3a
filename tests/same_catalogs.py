"""Two catalogs hold the same run: the same events (in any order of rows; the columns both formats store) and the
same task rows.

    python -m tests.same_catalogs A.h5 B.h5    # exit 0 when they do, else the first difference
"""
import sys

import numpy as np

from ensemble.store import reader, schema


def common_fields(attrs_a, attrs_b):
    """The event columns both catalogs store (those of the older format; the reader supplies the rest)."""
    a, b = (schema.STORED_EVENT_FIELDS[attrs["format"]] for attrs in (attrs_a, attrs_b))
    return [name for name in schema.EVENT_FIELDS if name in a and name in b]


def assert_same_events(path_a, path_b):
    a, ta, attrs_a = reader.read(path_a)
    b, tb, attrs_b = reader.read(path_b)
    assert len(a["t"]) == len(b["t"]) > 0, f"{len(a['t'])} and {len(b['t'])} events"
    order_a, order_b = np.lexsort((a["t"], a["task"])), np.lexsort((b["t"], b["task"]))
    for name in common_fields(attrs_a, attrs_b):
        np.testing.assert_array_equal(a[name][order_a], b[name][order_b], err_msg=name)
    for name in schema.TASK_FIELDS:
        np.testing.assert_array_equal(ta[name], tb[name], err_msg=name)


if __name__ == "__main__":
    assert_same_events(*sys.argv[1:3])
    print(f"{sys.argv[1]} and {sys.argv[2]}: the same events and tasks")
