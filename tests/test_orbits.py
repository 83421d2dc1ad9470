"""Where the family of periodic orbits ends, and what the emitted modules say there.

References that never call the package: exact edges (a cubic's saddle, π², e − 1), the first
integral of q'' + q + x q² q'² in closed form solved by mpmath, and SciPy's DOP853 shooting of
the scaled equation written out by hand (does the swing from u = 1 come back?).  The periods
for the error estimate come from the same shooting at rtol 1e-13, and from 40-digit quadrature
of the potential where there is one.
"""

from __future__ import annotations

import math
import zlib

import mpmath
import numpy as np
import pytest
from lindstedt.cli import main
from lindstedt.derive.models import model_from_text
from lindstedt.derive.orbits import orbit_domain
from lindstedt.emit.render import load_generated
from scipy.integrate import solve_ivp

mp = mpmath.mp


def swing(G, x: float, rtol: float = 1e-13, t_max: float = 200.0) -> float:
    """``T/2π`` of ``u'' + G(u, u', x) = 0`` from ``u = 1, u' = 0`` (time in units of 1/ω₀),
    by DOP853 to the next turning point ``u' = 0`` (the half period, by time reversibility);
    NaN where the swing does not come back (it runs off, or stalls at a saddle)."""
    if not G(1.0, 0.0, x) > 0:  # u = 1 at or beyond a saddle: no swing toward 0
        return math.nan

    def rhs(_t, y):
        return [y[1], -G(y[0], y[1], x)]

    def back(_t, y):
        return y[1]

    def gone(_t, y):
        return 1e3 - abs(y[0])

    back.terminal, back.direction = True, 1.0
    gone.terminal = True
    run = solve_ivp(rhs, (0.0, t_max), [1.0, 0.0], method="DOP853", rtol=rtol, atol=rtol * 1e-3,
                    events=(back, gone))
    if not len(run.t_events[0]):
        return math.nan
    return 2 * run.t_events[0][0] / (2 * math.pi)


# u'' + G(u, u', y) = 0 of each equation, written out by hand (time in units of 1/ω₀)
CASES = {
    "q'' + q + eps*q**2 = 0": lambda u, v, x: u + x * u**2,  # x = εA
    "q'' + q + eps*q**2*q'**2 = 0": lambda u, v, x: u + x * u**2 * v**2,  # x = εA³
    "q'' + q - q**2/2 - q**3/2 = 0": lambda u, v, A: u - A * u**2 / 2 - A**2 * u**3 / 2,
    "q'' + q*exp(-q) = 0": lambda u, v, A: u * math.exp(-A * u),
    "q'' + q - eps*(q**3 + q*q'**2) = 0": lambda u, v, x: u - x * (u**3 + u * v**2),
}


def edge(text: str) -> tuple[mpmath.mpf, mpmath.mpf]:
    d = orbit_domain(model_from_text(text, 4))
    assert d.known, d.how
    return mp.mpf(d.lower_text), mp.mpf(d.upper_text)


def test_edges_in_closed_form():
    with mp.workdps(40):
        # V = u²/2 + x u³/3: the saddle u = −1/x; V(1) = V(−1/x) at x = 1/2; x < −1: u = 1 is
        # beyond the saddle 1/|x|
        lo, hi = edge("q'' + q + eps*q**2 = 0")
        assert abs(hi - mp.mpf(1) / 2) < mp.mpf(10) ** -29 and abs(lo + 1) < mp.mpf(10) ** -29
        lo, hi = edge("q'' + sin(q) = 0")  # θ₀ < π, in θ₀²
        assert abs(hi - mp.pi**2) < mp.mpf(10) ** -28 and lo == -mp.inf
        lo, hi = edge("q'' + 2*q - q**3 = 0")  # the saddles at q² = 2
        assert abs(hi - 2) < mp.mpf(10) ** -29
        lo, hi = edge("q'' + log(1+q) = 0")  # V(−1) = 1 = V(A) at A = e − 1; A > −1
        assert abs(hi - (mp.e - 1)) < 1e-14 and abs(lo + 1) < 1e-14
        lo, hi = edge("q'' + q*exp(-q) = 0")  # V(+∞) = 1 = V(A) at A = −1
        assert abs(lo + 1) < mp.mpf(10) ** -28 and hi == mp.inf


def test_the_velocity_term_edge_by_its_own_first_integral():
    """q'' + q + x q² q'² = 0: with p = q'², (p e^{2xq³/3})' = −2q e^{2xq³/3}, so the swing
    from 1 comes back while ∫_{−∞}^{1} u e^{2xu³/3} du > 0; the edge is its zero."""
    with mp.workdps(40):
        def F(x):
            return mp.quad(lambda u: u * mp.exp(2 * x * u**3 / 3), [-mp.inf, 0, 1])

        truth = mp.findroot(F, mp.mpf("0.88"))
        _, hi = edge("q'' + q + eps*q**2*q'**2 = 0")
        assert abs(hi - truth) < mp.mpf(10) ** -25
    G = CASES["q'' + q + eps*q**2*q'**2 = 0"]
    assert math.isfinite(swing(G, float(hi) - 1e-3)) and math.isnan(swing(G, float(hi) + 1e-3))


@pytest.mark.parametrize("text", sorted(CASES))
def test_shooting_agrees_on_each_side_of_each_edge(text):
    lo, hi = edge(text)
    for bound, side in ((hi, 1), (lo, -1)):
        if mp.isinf(bound):
            assert math.isfinite(swing(CASES[text], 2.0 if side > 0 else -0.5, t_max=2000.0))
            continue
        b = float(bound)
        assert math.isfinite(swing(CASES[text], b - side * 1e-3 * abs(b)))
        assert math.isnan(swing(CASES[text], b + side * 1e-3 * abs(b)))


def emitted(tmp_path_factory, text: str, order: int, name: str):
    out = tmp_path_factory.mktemp(name)
    assert main(["generate", text, "--order", str(order), "--out", str(out), "--name", name]) == 0
    return load_generated(out / f"{name}.py")


EMITTED = [*(("q'' + q + eps*q**2 = 0", k) for k in (2, 4, 8, 16, 30)),
           ("q'' + q + eps*q**2*q'**2 = 0", 16), ("q'' + q - q**2/2 - q**3/2 = 0", 8),
           ("q'' + q*exp(-q) = 0", 8), ("q'' + q - eps*(q**3 + q*q'**2) = 0", 8)]


@pytest.mark.parametrize(("text", "order"), EMITTED)
def test_no_number_where_no_orbit_and_an_estimate_never_low(tmp_path_factory, text, order):
    """Beyond the edge (or the radius less its spread) every evaluator answers NaN; inside,
    wherever ``error_estimate`` is finite it bounds the true relative error of ``period``
    (against shooting at rtol 1e-13: 1e-11 of slack for the reference's own error)."""
    name = f"edge_{zlib.crc32(f'{text} {order}'.encode()):08x}"  # the same in every process
    mod = emitted(tmp_path_factory, text, order, name)
    lo, hi = (float(v) for v in edge(text))
    assert tuple(mod.ORBIT_LIMIT) == (lo, hi) or np.allclose(mod.ORBIT_LIMIT, (lo, hi),
                                                             rtol=1e-15)
    one = "eps" in text  # (A, eps) or A alone: the module's y is εA^p at A = 1, or A
    args = (lambda y: (1.0, y)) if one else (lambda y: (y,))
    outside = [v for v in (hi * 1.0001, hi * 1.2, hi + 0.5, lo * 1.0001, lo * 1.5)
               if math.isfinite(v)]
    for y in outside:
        assert math.isnan(mod.period(*args(y))) and math.isnan(mod.omega(*args(y)))
        assert math.isnan(mod.q(0.3, *args(y)))
        assert math.isnan(swing(CASES[text], y)) or not lo < y < hi
    span_lo = max(lo, -2.0) if math.isfinite(lo) else -2.0
    span_hi = min(hi, 2.0) if math.isfinite(hi) else 2.0
    checked = 0
    for y in np.linspace(span_lo, span_hi, 41)[1:-1]:
        T = mod.period(*args(y))
        estimate = mod.error_estimate(*args(y))
        if not (math.isfinite(T) and math.isfinite(estimate)):
            continue
        truth = 2 * math.pi * swing(CASES[text], y)
        assert abs(T - truth) / abs(T) <= estimate + 1e-11, (y, T, truth, estimate)
        checked += 1
    assert checked >= 10
