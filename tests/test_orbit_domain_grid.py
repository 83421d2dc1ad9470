"""Emitted modules whose parameter stays a symbol, on a grid of (A, parameter): NaN beyond the
orbit domain (the first integral's barrier), finite well inside it, and ``error_estimate`` at
least the true relative error of ``period`` wherever both are finite.

Four equations with a barrier: asymmetric (the issue's q² − q⁴), two-sided (softening
q − εq³), transcendental (sin q + k q³, k symbolic) and a velocity term (q q'²).  The truth
is independent of the generator: for ``q'' + g₀(q) + h(q) q'² = 0`` the first integral
``q'² e^{2H} = W(A) − W(q)`` (``H = ∫h``, ``W = ∫ 2 g₀ e^{2H}``, in closed form here), the
edges by ``mpmath.findroot`` on ``g₀ = 0`` and then on ``W(q) = W(saddle)``, and the period
``2∫ e^{H} dq / sqrt(W(A) − W(q))`` between the turning points by Gauss–Legendre quadrature,
accepted where two working precisions agree.  One module per equation, order 6 (each compile
costs ~10 s of CPU), emitted once for the file.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import mpmath as mp
import pytest
from lindstedt.cli import main
from lindstedt.emit.render import load_generated

ORDER = 6
INSIDE = (0.3, 0.7, 0.95)
# NOTE: A as fractions of the edge on each side: 0.3 must be answered (the radius guard may
# answer NaN nearer the edge, where T(ε) at that A is close to its singularity)
OUTSIDE = (1.02, 1.3)
AGREE = 1e-15
# NOTE: the quadrature at 25 and 35 digits must agree to this: the period is converged far
# below any truncation error compared with it


@dataclass(frozen=True)
class Case:
    """An equation, its parameter values, and its first integral in mpmath."""

    text: str
    values: tuple[float, ...]
    g0: Callable  # (q, p) -> g₀
    H: Callable  # (q, p) -> ∫₀^q h
    W: Callable  # (q, p) -> ∫₀^q 2 g₀ e^{2H}


def _W_velocity(q, e):
    """``∫₀^q 2(u + e u²) e^{e u²} du`` in closed form (erfi; complex for e < 0)."""
    q, e = mp.mpf(q), mp.mpf(e)
    r = mp.sqrt(mp.mpc(e))
    value = ((mp.exp(e * q**2) - 1) / e + q * mp.exp(e * q**2)
             - mp.sqrt(mp.pi) * mp.erfi(r * q) / (2 * r))
    return mp.re(value)


CASES = {
    "asymmetric": Case("q'' + q + eps*(q**2 - q**4) = 0", (0.1, 0.3),
                       lambda q, e: q + e * (q**2 - q**4), lambda q, e: 0,
                       lambda q, e: q**2 + 2 * e * (q**3 / 3 - q**5 / 5)),
    "two-sided": Case("q'' + q - eps*q**3 = 0", (0.1, 0.4),
                      lambda q, e: q - e * q**3, lambda q, e: 0,
                      lambda q, e: q**2 - e * q**4 / 2),
    "transcendental": Case("q'' + sin(q) + k*q**3 = 0", (-0.05, 0.01),
                           lambda q, k: mp.sin(q) + k * q**3, lambda q, k: 0,
                           lambda q, k: 2 * (1 - mp.cos(q)) + k * q**4 / 2),
    "exponential": Case("q'' + q*exp(-a*q) = 0", (0.5, 1.0),
                        lambda q, a: q * mp.exp(-a * q), lambda q, a: 0,
                        lambda q, a: 2 * (1 - (1 + a * q) * mp.exp(-a * q)) / a**2),
    "velocity": Case("q'' + q + eps*(q**2 + q*q'**2) = 0", (0.2, -0.3),
                     lambda q, e: q + e * q**2, lambda q, e: e * q**2 / 2, _W_velocity),
}


class _Modules(dict):
    """Each case's module, written by ``lindstedt generate`` and loaded when its test first
    asks (a worker compiles only its own cases')."""

    def __init__(self, out) -> None:
        super().__init__()
        self.out = out

    def __missing__(self, key: str):
        name = "grid_" + key.replace("-", "_")
        assert main(["generate", CASES[key].text, "--order", str(ORDER), "--out",
                     str(self.out), "--name", name]) == 0
        self[key] = load_generated(self.out / f"{name}.py")
        return self[key]


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    """The cases' modules, each emitted once for the file when first used."""
    return _Modules(tmp_path_factory.mktemp("domain_grid"))


def _zero(case: Case, p, side: int):
    """The zero of g₀ nearest 0 on ``side`` (None: none out to |q| = 30), by a scan and
    ``mp.findroot``."""
    step, q = mp.mpf("0.01"), mp.mpf("0.01")
    before = case.g0(side * q, p) * side
    while q < 30:
        after = case.g0(side * (q + step), p) * side
        if before * after <= 0:
            return mp.findroot(lambda x: case.g0(x, p), (side * q, side * (q + step)),
                               solver="anderson")
        before, q = after, q + step
    return None


def _level_crossing(case: Case, p, level, side: int):
    """The q on ``side`` of 0 where W first reaches ``level`` (W(0) = 0 below it): a scan,
    then ``mp.findroot`` in the bracket (None: not within |q| < 30)."""
    step, q = mp.mpf("0.01"), mp.mpf("0.01")
    while q < 30:
        if case.W(side * (q + step), p) >= level:
            return mp.findroot(lambda x: case.W(x, p) - level, (side * q, side * (q + step)),
                               solver="anderson")
        q += step
    return None


def _limit(case: Case, p, side: int):
    """``W(side·∞)`` (inf: unbounded), by quadrature of ``2 g₀ e^{2H}``."""
    value = mp.quad(lambda u: 2 * case.g0(u, p) * mp.exp(2 * case.H(u, p)),
                    [0, side * mp.inf])
    return abs(value) if mp.isfinite(value) and abs(value) < 1e30 else mp.inf


def edges(case: Case, p) -> tuple[float, float]:
    """The amplitudes ``lo < 0 < hi`` where the family through ``q = 0`` ends at ``p``: on each
    side the saddle (a zero of g₀) or, first, the level of the barrier on the other side."""
    with mp.workdps(30):
        p = mp.mpf(p)
        found = []
        for side in (+1, -1):
            z = _zero(case, p, side)
            other = _zero(case, p, -side)
            barrier = case.W(other, p) if other is not None else _limit(case, p, -side)
            if z is not None and case.W(z, p) <= barrier:
                found.append(float(z))
                continue
            # W rises on this side: it may meet the other side's barrier level first
            crossing = _level_crossing(case, p, barrier, side) if mp.isfinite(barrier) else None
            found.append(side * math.inf if crossing is None else float(crossing))
        return found[1], found[0]


def _period_at(case: Case, A, p, dps: int):
    """``2∫ e^{H} / sqrt(W(A) − W(q))`` between the turning points at ``dps`` digits, with
    ``u²`` substitutions at both ends."""
    with mp.workdps(dps):
        a, pp = mp.mpf(A), mp.mpf(p)
        WA = case.W(a, pp)
        b = _level_crossing(case, pp, WA, -1 if a > 0 else 1)
        assert b is not None, (case.text, A, p)
        lo, hi = sorted((a, b))
        mid = (lo + hi) / 2

        def f(q):
            return mp.exp(case.H(q, pp)) / mp.sqrt(WA - case.W(q, pp))

        return 2 * (mp.quad(lambda u: 2 * u * f(hi - u * u), [0, mp.sqrt(hi - mid)],
                            method="gauss-legendre")
                    + mp.quad(lambda u: 2 * u * f(lo + u * u), [0, mp.sqrt(mid - lo)],
                              method="gauss-legendre"))


def true_period(case: Case, A, p) -> float:
    """The period through ``q(0) = A`` at 25 and 35 digits, which must agree."""
    coarse, fine = (_period_at(case, A, p, dps) for dps in (25, 35))
    assert abs(coarse / fine - 1) < AGREE, (case.text, A, p, coarse, fine)
    return float(fine)


@pytest.mark.parametrize("key", list(CASES))
def test_symbolic_parameter_module_on_a_grid_against_quadrature(modules, key):
    """On a grid of (A, p) per equation: NaN past the edge, finite at 0.3 of it, and
    error_estimate ≥ |period/T − 1| wherever both are finite."""
    case, module = CASES[key], modules[key]
    with mp.workdps(30):  # the closed-form W agrees with its defining integral
        q, p = mp.mpf("0.7"), mp.mpf(case.values[0])
        assert mp.almosteq(mp.diff(lambda x: case.W(x, p), q),
                           2 * case.g0(q, p) * mp.exp(2 * case.H(q, p)), 1e-20)
    checked = 0
    for p in case.values:
        lo, hi = edges(case, p)
        for edge in (lo, hi):
            if math.isinf(edge):
                continue
            for f in OUTSIDE:
                A = f * edge
                assert math.isnan(module.period(A, p)), (key, A, p, edge)
                assert math.isnan(module.error_estimate(A, p)), (key, A, p, edge)
            for f in INSIDE:
                A = f * edge
                T, bound = module.period(A, p), module.error_estimate(A, p)
                if f == INSIDE[0]:
                    assert math.isfinite(T) and math.isfinite(bound), (key, A, p, edge)
                if math.isnan(T) or math.isnan(bound):
                    continue
                error = abs(T / true_period(case, A, p) - 1)
                assert error <= bound, (key, A, p, edge, error, bound)
                checked += 1
    assert checked >= 6, (key, checked)
