"""The adaptive IMEX integrator ARK4(3): its tableau, error against the tolerance, energy, CLI."""
import functools
from fractions import Fraction

import numba as nb
import numpy as np
import pytest

from ensemble.config import Integrator, Model
from ensemble.events import check, run_event
from ensemble.integrators import kernel_params
from ensemble.model.methods import take_step
from ensemble.model.steppers import FIRST_NEW
from ensemble.model.tableaux import ARK324, ARK436, ARK548
from ensemble.model.workspace import (NTRACE, P, P0, T_BLOCK, T_ERROR, T_H, T_OWN, T_PART, T_SLIDING, T_TAU, V,
                                      V0, Y, Y0, YS, Workspace)

from .conftest import run_cli, write_config

# The published 13-digit fractions satisfy the conditions to about 1e-26 (measured at most
# 3.1e-26); a change of one unit in the last digit of any coefficient shows at 1e-14 or more
# (measured: the least visible such change leaves a residual of 2.3e-14).
TOL = 1e-20


def dot(u, w):
    return sum(x * y for x, y in zip(u, w))


def mul(A, x):
    return [dot(row, x) for row in A]


def power(x, k):
    return [xi ** k for xi in x]


def times(u, w):
    return [x * y for x, y in zip(u, w)]


def order_residuals(b, c, tableaux, order):
    """Residuals of the order conditions up to `order` (at most 5) of an additive RK method.

    All tableaux share b and c (row sums), so the conditions are those of the
    trees with every colouring of their inner nodes by a tableau. (The vectors A c, A c^2 and
    A B c are formed once and shared between the trees that contain them: exact fractions with
    13-digit numerators are slow.)
    """
    out = {"b.1": dot(b, [1] * len(b)) - 1}
    if order >= 2:
        out["b.c"] = dot(b, c) - Fraction(1, 2)
    if order < 3:
        return out
    c2 = power(c, 2)
    Ac = {p: mul(A, c) for p, A in tableaux.items()}
    out["b.c2"] = dot(b, c2) - Fraction(1, 3)
    for p in tableaux:
        out[f"b.{p}c"] = dot(b, Ac[p]) - Fraction(1, 6)
    if order < 4:
        return out
    Ac2 = {p: mul(A, c2) for p, A in tableaux.items()}
    ABc = {(p, q): mul(A, Ac[q]) for p, A in tableaux.items() for q in tableaux}
    out["b.c3"] = dot(b, power(c, 3)) - Fraction(1, 4)
    for p in tableaux:
        out[f"b.(c*{p}c)"] = dot(b, times(c, Ac[p])) - Fraction(1, 8)
        out[f"b.{p}c2"] = dot(b, Ac2[p]) - Fraction(1, 12)
        for q in tableaux:
            out[f"b.{p}{q}c"] = dot(b, ABc[p, q]) - Fraction(1, 24)
    if order < 5:
        return out
    out["b.c4"] = dot(b, power(c, 4)) - Fraction(1, 5)
    for p, A in tableaux.items():
        out[f"b.(c2*{p}c)"] = dot(b, times(c2, Ac[p])) - Fraction(1, 10)
        out[f"b.(c*{p}c2)"] = dot(b, times(c, Ac2[p])) - Fraction(1, 15)
        out[f"b.{p}c3"] = dot(b, mul(A, power(c, 3))) - Fraction(1, 20)
        for q in tableaux:
            out[f"b.(c*{p}{q}c)"] = dot(b, times(c, ABc[p, q])) - Fraction(1, 30)
            out[f"b.({p}c*{q}c)"] = dot(b, times(Ac[p], Ac[q])) - Fraction(1, 20)
            out[f"b.{p}(c*{q}c)"] = dot(b, mul(A, times(c, Ac[q]))) - Fraction(1, 40)
            out[f"b.{p}{q}c2"] = dot(b, mul(A, Ac2[q])) - Fraction(1, 60)
            for r in tableaux:
                out[f"b.{p}{q}{r}c"] = dot(b, mul(A, ABc[q, r])) - Fraction(1, 120)
    return out


@functools.cache
def residuals(pair, embedded, order):
    """order_residuals up to `order` of an ArkPair's weights b, or bhat if `embedded`: once per pair, order and
    weights (the test of mistyped digits reads them twice)."""
    c, ae, ai, b, bhat = pair.matrices()
    return order_residuals(bhat if embedded else b, c, {"E": ae, "I": ai}, order)


def violations(pair):
    """What is wrong with an ArkPair's coefficients, in exact fractions (empty if nothing)."""
    c, ae, ai, b, bhat = pair.matrices()
    s = len(c)
    out = []
    for A, name in ((ae, "explicit"), (ai, "implicit")):
        out += [f"{name} row {i} does not sum to c" for i in range(s) if abs(sum(A[i]) - c[i]) > TOL]
    if any(ae[i][j] != 0 for i in range(s) for j in range(i, s)):
        out.append("explicit tableau not strictly lower")
    if ai[0][0] != 0 or any(ai[i][i] != Fraction(pair.gamma) for i in range(1, s)):
        out.append("implicit tableau not ESDIRK")
    if ai[-1] != b:
        out.append("implicit tableau not stiffly accurate")
    for embedded, order in ((False, pair.order), (True, pair.embedded_order)):
        out += [f"order {order}: {k} = {float(r):.1e}"
                for k, r in residuals(pair, embedded, order).items() if abs(r) > TOL]
    # the embedded method is of order q, not q + 1 (else the estimate would vanish)
    if max(abs(r) for r in residuals(pair, True, pair.order).values()) < 1e-4:
        out.append("embedded method of the same order")
    return out


@pytest.mark.parametrize("pair", [ARK324, ARK436, ARK548], ids=lambda p: p.name)
def test_tableau_order_conditions(pair):
    """Exact-fraction check of the coefficients the kernels use."""
    c, ae, ai, b, bhat = pair.matrices()
    for weights, order in ((b, pair.order), (bhat, pair.embedded_order)):
        worst = max(abs(r) for r in order_residuals(weights, c, {"E": ae, "I": ai}, order).values())
        print(f"{pair.name}: largest order-{order} residual {float(worst):.1e}")
    assert violations(pair) == []


def _with_last_digit_changed(pair, field, *index):
    """A copy of `pair` with the numerator of one coefficient changed by one unit."""
    def change(x):
        num, _, den = x.partition("/")
        return f"{int(num) + 1}/{den}" if den else str(int(num) + 1)

    value = getattr(pair, field)
    if not index:
        return pair._replace(**{field: change(value)})
    rows = [list(r) if isinstance(r, tuple) else r for r in value]
    if len(index) == 1:
        rows[index[0]] = change(rows[index[0]])
    else:
        rows[index[0]][index[1]] = change(rows[index[0]][index[1]])
    return pair._replace(**{field: tuple(tuple(r) if isinstance(r, list) else r for r in rows)})


@pytest.mark.parametrize("pair", [ARK324, ARK436, ARK548], ids=lambda p: p.name)
def test_a_mistyped_digit_is_caught(pair):
    """Every coefficient changed by one unit in its last digit breaks some condition by more than TOL."""
    mutants = [_with_last_digit_changed(pair, "gamma")]
    for field in ("c", "b", "bhat"):
        mutants += [_with_last_digit_changed(pair, field, i) for i in range(len(getattr(pair, field)))]
    for field in ("explicit", "implicit"):
        rows = getattr(pair, field)
        mutants += [_with_last_digit_changed(pair, field, i, j) for i in range(len(rows))
                    for j in range(len(rows[i]))]
    def worst(p):
        c, ae, ai, b, bhat = p.matrices()
        rows = [abs(sum(A[i]) - c[i]) for A in (ae, ai) for i in range(len(c))]
        rows += [abs(r) for embedded, o in ((False, p.order), (True, p.embedded_order))
                 for r in residuals(p, embedded, o).values()]
        rows += [abs(ai[-1][j] - b[j]) for j in range(len(b))]
        return max(rows)
    print(f"{pair.name}: smallest largest residual of a mutant {float(min(worst(m) for m in mutants)):.1e}")
    assert all(violations(m) for m in mutants)


@pytest.mark.parametrize("pair", [ARK324, ARK436, ARK548], ids=lambda p: p.name)
def test_implicit_part_is_l_stable_at_infinity(pair):
    """R(z) = 1 + z b^T (I - z A_I)^-1 1 vanishes as z -> -inf (stiff decay of the state)."""
    _, _, ai, b, _ = pair.matrices()
    A = np.array(ai, dtype=float)
    bw = np.array(b, dtype=float)
    one = np.ones(len(bw))
    for z in (-1e6, -1e9):
        r = 1 + z * bw @ np.linalg.solve(np.eye(len(bw)) - z * A, one)
        print(f"{pair.name}: |R({z:.0e})| = {abs(r):.1e}")
        # R(z) ~ C / z: measured 2.9e-6 .. 9.3e-6 at z = -1e6 (exact arithmetic would give the
        # same: no round-off margin needed), 2.8e-9 .. 5.1e-7 at -1e9 (there round-off of the
        # solve dominates); an implicit part that is A- but not L-stable gives |R| ~ 1
        assert abs(r) < 1e-5


def test_kernel_arrays_are_the_tableau():
    c, ae, ai, b, bd, g = ARK436.kernel_arrays()
    cf, aef, aif, bf, bhatf = ARK436.matrices()
    assert g == 0.25 and np.all(np.diag(ai) == 0)
    np.testing.assert_array_equal(ae, np.array(aef, dtype=float))
    diagonal = g * np.diag([0.0] + [1.0] * 5)
    print(f"implicit tableau {np.max(np.abs(ai + diagonal - np.array(aif, dtype=float))):.1e}, error weights "
          f"{np.max(np.abs(bd - (np.array(bf, dtype=float) - np.array(bhatf, dtype=float)))):.1e} off the fractions")
    # measured: both exactly equal to the fractions rounded to float64; the bounds allow an ulp
    np.testing.assert_allclose(ai + diagonal, np.array(aif, dtype=float), rtol=1e-15)
    np.testing.assert_allclose(bd, np.array(bf, dtype=float) - np.array(bhatf, dtype=float), atol=1e-16)


@nb.njit(cache=True)
def step(W, act, na, n, tau, h, p, yrest):
    """One step of the method p.method (the kernels' call, methods.take_step, every stage evaluated):
    (friction work, slip integral, error norm). Cached with the kernels (in the directory named after their
    sources, so a change to them compiles it again): compiling it took about 20 s."""
    return take_step(W, act, na, n, tau, h, p, yrest, FIRST_NEW, (0.0, 0.0))[:3]


@pytest.mark.parametrize("method", ["ark3", "ark4", "ark5"])
def test_zero_step_keeps_the_state(method):
    """The event kernel redoes a step with h = 0 when an onset is located at its start."""
    rng = np.random.default_rng(0)
    ws = Workspace(8)
    ws.load(rng.normal(size=8), rng.normal(size=8))
    act = np.array([2, 3, 4, 0, 0, 0, 0, 0])
    W = ws.W
    W[:, Y0] = W[:, Y] = W[:, YS] = rng.random(8)
    W[:, V0] = rng.random(8) * 100
    W[:, P0] = W[:, P]
    params = kernel_params(Model(l=3.0, nu=1e-8, a=0.0, b=20.0), Integrator(method=method, rtol=1e-6, atol=1e-12))
    _, _, err = step(W, act, 3, 8, 0.5, 0.0, params, 0.0)
    assert err == 0.0
    for new, old in ((Y, Y0), (V, V0), (P, P0)):
        np.testing.assert_array_equal(W[act[:3], new], W[act[:3], old])


def _slide(method, steps, duration=0.5):
    """(y, v, psi) of one block sliding between two at rest, `steps` fixed steps of `method`."""
    n, psi0 = 3, 0.5
    ws = Workspace(n)
    ws.load(np.array([0.0, 20.0 * psi0 + 3.0, 0.0]), np.full(n, psi0))
    W = ws.W
    act = np.array([1, 0, 0])
    W[1, V] = 5.0
    h = duration / steps
    params = kernel_params(Model(l=3.0, nu=1e-8, a=2.0, b=20.0), Integrator(method=method, rtol=1e-6, atol=1e-12))
    for k in range(steps):
        W[1, Y0], W[1, V0], W[1, P0] = W[1, Y], W[1, V], W[1, P]
        step(W, act, 1, n, k * h, h, params, 0.0)
    return np.array([W[1, Y], W[1, V], W[1, P]])


@pytest.mark.parametrize("method, order", [("ark3", 3), ("ark4", 4), ("ark5", 5)])
def test_convergence_order_with_fixed_steps(method, order):
    """Errors of slip, velocity and state fall as h^p (the block keeps sliding: smooth)."""
    ref = _slide("ark5", 4000)
    errors = [np.abs(_slide(method, m) - ref) for m in (20, 40, 80)]
    observed = np.log2(errors[1] / errors[2])
    print(f"observed orders (y, v, psi): {observed.round(2)}")
    # measured 2.92 .. 2.99, 3.81 .. 3.99 and 5.00 (largest deviation 0.19)
    assert np.all(np.abs(observed - order) < 0.3)


# relative slip error bounds at rtol 1e-5 and 1e-7: the tolerance itself. Measured on the four
# events at rtol 1e-5 / 1e-7: ark3 at most 5.9e-7 / 6.2e-9, ark4 9.7e-7 / 6.0e-9, ark5 5.1e-7 / 5.0e-9
# (at most 0.1 rtol; the reference, RK4 at dt 1.25e-4, is good to ~1e-10).
ERROR_BOUNDS = {"ark3": (1e-5, 1e-7), "ark4": (1e-5, 1e-7), "ark5": (1e-5, 1e-7)}


@pytest.mark.parametrize("method", sorted(ERROR_BOUNDS))
def test_slip_error_follows_the_tolerance(events, method):
    model, evs = events
    for f, p, epicenter, ref in evs:
        errors = []
        for rtol in (1e-5, 1e-7):
            ev = check(run_event(f, p, epicenter, model, Integrator(method=method, rtol=rtol)))
            errors.append(abs(ev.slip - ref.slip) / ref.slip)
            profile_error = np.linalg.norm(ev.profile - ref.profile) / np.linalg.norm(ref.profile)
            print(f"  rtol {rtol:.0e}: profile error {profile_error / rtol:.2f} rtol, "
                  f"energy residual {ev.relative_energy_residual / rtol:.2e} rtol")
            # measured: profile error at most 0.10 rtol, energy residual 0.046 rtol
            assert np.linalg.norm(ev.profile - ref.profile) <= rtol * np.linalg.norm(ref.profile)
            assert ev.relative_energy_residual < rtol
        print(f"slip {ref.slip:.3g}: relative errors at rtol 1e-5, 1e-7: {errors[0]:.1e}, {errors[1]:.1e}")
        assert errors[0] < ERROR_BOUNDS[method][0] and errors[1] < ERROR_BOUNDS[method][1]
        # 100x less tolerance, at least 10x less error (measured 25-160x), unless the error is
        # already near the reference's own (ark5: 1.1e-9 -> 1.7e-10)
        assert errors[1] < errors[0] / 10 or errors[1] < 1e-9


def test_fewer_steps_than_ark3_at_the_same_tolerance(events):
    model, evs = events
    f, p, epicenter, ref = evs[0]
    ark3 = check(run_event(f, p, epicenter, model, Integrator(method="ark3", rtol=1e-6)))
    ark4 = check(run_event(f, p, epicenter, model, Integrator(method="ark4", rtol=1e-6)))
    print(f"block-steps at rtol 1e-6: ark3 {ark3.block_steps}, ark4 {ark4.block_steps}; slip errors "
          f"{abs(ark3.slip / ref.slip - 1):.1e}, {abs(ark4.slip / ref.slip - 1):.1e}")
    # measured 3.3x fewer block-steps (54772 against 183328), slip errors 4.3e-9 against 6.4e-8
    assert ark4.block_steps < ark3.block_steps / 2
    assert abs(ark4.slip - ref.slip) < abs(ark3.slip - ref.slip)


@pytest.mark.parametrize("method", ["rk4", "ark4", "ark5"])
def test_step_trace_accounts_for_every_step(events, method):
    """Tracing does not change the event, and its rows add up to the event's step counts."""
    model, evs = events
    integrator = Integrator(method=method, rtol=1e-6)
    for f, p, epicenter, _ in evs:
        plain = check(run_event(f, p, epicenter, model, integrator))
        trace = np.full((plain.steps + 5, NTRACE), np.nan)
        traced = check(run_event(f, p, epicenter, model, integrator, trace=trace))
        assert traced.slip == plain.slip and traced.steps == plain.steps
        assert np.isnan(trace[plain.steps:]).all()
        rows = trace[:plain.steps]
        accepted = rows[:, T_ERROR] <= 1.0
        assert np.sum(~accepted) == plain.rejected
        assert rows[accepted, T_SLIDING].sum() == plain.block_steps
        # accepted steps follow each other (a cut step ends before the next starts)
        tau, h = rows[accepted, T_TAU], rows[accepted, T_H]
        print(f"{method}: largest overlap of consecutive steps {np.max(np.diff(tau) - h[:-1]):.1e} "
              f"({np.max((np.diff(tau) - h[:-1]) / tau[1:]):.1e} of the time)")
        # (round-off of the sums: measured at most 1.4e-16 of the time)
        assert np.all(np.diff(tau) > 0) and np.all(np.diff(tau) <= h[:-1] + 1e-14 * tau[1:])
        if method == "rk4":
            assert np.all(rows[:, T_BLOCK] == -1) and np.all(rows[:, T_ERROR] == 0)
        else:
            blocks = rows[:, T_BLOCK]
            assert np.all((blocks >= 0) & (blocks < len(f))) and set(rows[:, T_PART]) <= {0, 1, 2}
            # a block whose own error is largest takes the common step: own-step block-steps are
            # between a tenth of the sliding blocks and all of them, and at least one per step
            own = rows[accepted, T_OWN]
            sliding = rows[accepted, T_SLIDING]
            print(f"  own-step block-steps: largest excess over the sliding blocks "
                  f"{np.max(own - sliding):.1e}, "
                  f"over the lower bound {np.min(own - np.maximum(1.0, 0.1 * sliding)):.1e}")
            # (1e-12: round-off slack of the sum; measured: both bounds reached exactly, never passed)
            assert np.all(own <= sliding + 1e-12) and np.all(own >= np.maximum(1.0, 0.1 * sliding) - 1e-12)


@pytest.mark.parametrize("method", ["ark4", "ark5"])
def test_pi_control_keeps_rejections_rare(events, method):
    """PI step control: at most 12% of the steps tried are rejected (measured 2.4-9.1% on these events;
    the plain controller 0.9 err^(-1/(q+1)) rejected ~20% on large events)."""
    model, evs = events
    for f, p, epicenter, _ in evs:
        ev = check(run_event(f, p, epicenter, model, Integrator(method=method, rtol=1e-5)))
        print(f"{method}: {ev.rejected} of {ev.steps} steps rejected")
        assert ev.rejected <= 0.12 * ev.steps


def test_run_with_ark4(tmp_path):
    cfg = write_config(tmp_path / "c.toml", integrator={"method": "ark4", "rtol": 1e-6},
                       run={"seeds": 1, "events": 30, "transient": 10})
    res = run_cli("run", cfg, "-o", tmp_path / "a.h5")
    assert res.returncode == 0, res.stderr
