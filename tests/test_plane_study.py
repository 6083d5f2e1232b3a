"""examples/plane/study.py's measures of a plane's events (docs/plane.md) on hand-built events with known answers."""
import numpy as np

from examples.plane.study import CHUNKS, boundary, numbers, past_rims, rim, rim_numbers, stretches


def test_the_rim_of_a_rupture_zone_is_its_blocks_beside_another_or_beside_the_edge():
    """A 3 x 3 zone inside a 6 x 5 plane: its 8 outer blocks; a zone against the plane's edge: the edge's blocks
    are rim too; a lone block is its own rim."""
    N, M = 6, 5
    zone = np.zeros((M, N), bool)
    zone[1:4, 1:4] = True
    assert rim(zone.ravel(), N, M).reshape(M, N).sum() == 8
    assert not rim(zone.ravel(), N, M).reshape(M, N)[2, 2]
    zone = np.zeros((M, N), bool)
    zone[0:3, 0:3] = True           # in the corner: (0, 0) and the edges' blocks are rim, (1, 1) is not
    r = rim(zone.ravel(), N, M).reshape(M, N)
    assert r[0, 0] and r[0, 1] and r[2, 2] and not r[1, 1]
    assert rim(np.eye(1, N * M, 7, dtype=bool)[0], N, M).sum() == 1


def test_an_epicenter_on_the_rim_against_its_share_of_the_zone():
    """Two zones of 10 x 10 on a 20 x 20 plane (rim 36 of 100 blocks), one with its epicenter on the rim, one in
    the middle: half of the epicenters on the rim, and the rim's share 0.36; a zone below LARGE_BLOCKS is left out."""
    N = M = 20
    zone = np.zeros((M, N), bool)
    zone[5:15, 5:15] = True
    kept = [{"slip": zone.ravel() * 1.0, "epicenter": 5 * N + 9},      # (x 9, y 5): the zone's lower rim
            {"slip": zone.ravel() * 1.0, "epicenter": 10 * N + 10},    # its middle
            {"slip": np.eye(1, N * M, 3)[0], "epicenter": 3}]          # one block: too small
    r = rim_numbers(N, M, kept)
    assert (r["kept"], r["epicenter_on_rim"], r["rim_share_of_zone"]) == (2, 0.5, 0.36)
    assert 0.09 < r["epicenter_on_rim_interval"][0] < 0.5 < r["epicenter_on_rim_interval"][1] < 0.91


def test_unilateral_ruptures_and_shapes_count_only_ruptures_bounded_by_their_own_ends():
    """On a 100 x 10 plane: a rupture over x 10..59 from x = 12 (within a tenth of its length of an end), one over
    20..69 from x = 45 (in the middle), one over the whole length (not counted: its ends are the fault's), and a
    small one (below LARGE_BLOCKS); the shape's extent along over across strike of the first alone, 50 / 5 (the
    second reaches the plane's sides)."""
    N, M = 100, 10
    ev = {"mu": np.array([4.0, 4.0, 5.0, 1.0]), "n_slipped": np.array([250, 500, 1000, 1]), "N": N,
          "first": np.array([10, 20, 0, 3]), "last": np.array([59, 69, 99, 3]),
          "across_first": np.array([1, 0, 0, 0]), "across_last": np.array([5, 9, 9, 0]),
          "epicenter": np.array([12 + N * 2, 45 + N * 5, 50, 3])}
    r = numbers(ev, N * M)
    assert (r["large"], r["large_own_ends"], r["large_own_shape"]) == (3, 2, 1)
    assert r["unilateral"] == 0.5 and r["anisotropy_median"] == 10.0
    assert r["whole"] == 0.25 and r["spanning"] == 0.25
    # near the fault's edges (a tenth of 100 along, of 10 across): the third alone (y = 0); uniform chance 0.36
    assert r["near_edge"] == 1 / 3 and r["edge_chance"] == 1 - 0.8 ** 2


def test_shapes_by_size_measure_elongation_either_way_and_how_much_of_the_box_slipped():
    """On a 100 x 100 plane, three bounded ruptures: 20 x 10 blocks full (200 blocks: along / across 2, elongation
    2, fill 1), 10 x 20 with half its box slipped (100 blocks: 0.5, 2, 0.5) and 40 x 40 with 1000 blocks (1, 1,
    0.625); their bins of size 100-199, 200-399 and 800-1599; the medians over all three: 1, 2 and 0.625. A
    fourth, 30 x 10 from the plane's end along strike (its shape cut by the edge), is left out."""
    N, M = 100, 100
    ev = {"mu": np.full(4, 4.0), "n_slipped": np.array([200, 100, 1000, 300]), "N": N,
          "first": np.array([10, 50, 30, 0]), "last": np.array([29, 59, 69, 29]),
          "across_first": np.array([1, 30, 50, 60]), "across_last": np.array([10, 49, 89, 69]),
          "epicenter": np.array([10, 50 + 30 * N, 30 + 50 * N, 60 * N])}
    r = numbers(ev, N * M)
    assert r["large_own_shape"] == 3
    assert (r["anisotropy_median"], r["elongation_median"], r["fill_median"]) == (1.0, 2.0, 0.625)
    s = r["by_size"]
    assert s["count"] == [1, 1, 0, 1, 0]
    assert s["along_over_across"][:2] == [0.5, 2.0] and s["elongation"][:2] == [2.0, 2.0]
    assert s["fill"][0] == 0.5 and s["fill"][3] == 0.625 and np.isnan(s["fill"][2])


def test_an_epicenter_next_to_a_past_zones_edge_against_the_other_epicenters():
    """On a 10 x 10 plane: the boundary of a 4 x 4 zone inside it is its 12 outer blocks and the 16 outside them;
    of a zone against the plane's edge, the blocks on either side of its one inner edge. Three kept events: A (the
    4 x 4 zone, epicenter in its middle), B (the whole plane, epicenter on A's edge) and C (epicenter in the far
    corner): B is next to A's edge, C is not (B's zone is the whole plane: no edge); against the others'
    epicenters: none next to A's edge for B, B's own for C (one of two)."""
    N = M = 10
    zone = np.zeros((M, N), bool)
    zone[2:6, 2:6] = True
    assert boundary(zone.ravel(), N, M).sum() == 28
    edge = np.zeros((M, N), bool)
    edge[:, :3] = True
    b = boundary(edge.ravel(), N, M).reshape(M, N)
    assert b.sum() == 20 and b[:, 2].all() and b[:, 3].all() and not b[:, 0].any()
    kept = [{"slip": zone.ravel() * 1.0, "epicenter": 3 * N + 3},
            {"slip": np.ones(N * M), "epicenter": 2 * N + 6},        # (x 6, y 2): just outside A
            {"slip": np.ones(N * M), "epicenter": 9 * N + 9}]
    hits, chance = past_rims(N, M, kept)
    assert hits == [True, False] and chance == [0.0, 0.5]


def test_the_bootstraps_stretches_of_pooled_seeds_never_span_the_seam():
    """Seeds of 31 and 9 events (a seam at 30 | 31 where 20 equal stretches would cut 30, 31 together): 16 stretches
    of the first, 4 of the second, every event once, in order; one seed alone: CHUNKS stretches."""
    cuts = stretches([31, 9])
    assert len(cuts) == CHUNKS and np.array_equal(np.concatenate(cuts), np.arange(40))
    assert all(c.max() < 31 or c.min() >= 31 for c in cuts)
    assert sum(c.max() < 31 for c in cuts) == 16
    assert len(stretches([1000])) == CHUNKS


def test_an_epicenter_at_a_side_of_its_ruptures_box_against_the_boxs_share():
    """On a 100 x 100 plane, three bounded ruptures of 21 x 11 blocks (a band of 3 columns at either end along, of 2
    rows at either side across): epicenters at the box's left side, at its top side and in its middle: two of three
    at a side, where the box's share is 1 - (1 - 6 / 21) (1 - 4 / 11); a rupture touching the plane's edge is left
    out."""
    N = M = 100
    first, across_first = np.array([10, 40, 60, 0]), np.array([10, 30, 60, 5])
    x = first + np.array([2, 10, 10, 1])            # 2 from the left end (<= 0.1 * 20), the middle, the middle
    y = across_first + np.array([5, 9, 5, 1])       # the middle, 1 from the top (<= 0.1 * 10), the middle
    ev = {"mu": np.full(4, 4.0), "n_slipped": np.full(4, 231), "N": N, "first": first, "last": first + 20,
          "across_first": across_first, "across_last": across_first + 10, "epicenter": x + N * y}
    r = numbers(ev, N * M)
    assert r["large_own_shape"] == 3 and r["box_side"] == 2 / 3
    assert abs(r["box_side_chance"] - (1 - (1 - 6 / 21) * (1 - 4 / 11))) < 1e-12
