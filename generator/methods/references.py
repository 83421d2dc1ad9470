"""The methods' references: the free Duffing period (mpmath, 30 digits), quadrature of any
free oscillator's period, cn, integrated periods; the driven methods at one ω and their
emitted modules run on a grid."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import mpmath
import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipj

from ..analysis.driven import (
    Branch,
    Drive,
    amplitudes,
    harmonic_balance,
    mu_expansion,
    one_harmonic,
)
from ..derive.models import Model
from ..numerics.newton import safeguarded
from ..numerics.shooting import shoot

Solved = tuple[bool, tuple[dict, dict]]
# NOTE: a driven method at one ω and order: (converged, (A, B)).
Emitted = tuple[np.ndarray, np.ndarray, Callable[[], object], int]
# NOTE: a driven method's emitted module run on a grid: (A, B, the module's call, its order).


def _solve_mu(d: Drive, branch: Branch, order: int) -> Solved:
    mu = mu_expansion(d, branch, order)
    ok = len(mu.coefficients) > order and mu.converged
    return ok, amplitudes(*mu.partial(min(order, len(mu.coefficients) - 1)), 5)


def _solve_balance(d: Drive, branch: Branch, order: int) -> Solved:
    hb = harmonic_balance(d, branch, order)
    return hb.converged, amplitudes(hb.coefficients, 0.0, 5)


def _solve_shooting(d: Drive, branch: Branch, order: int) -> Solved:
    guess = branch.A1 * np.array([np.cos(branch.delta0), d.omega * np.sin(branch.delta0)])
    orbit = shoot(d.eps, d.force, d.omega, d.damping, guess, steps=order)
    return (True, (orbit.A, orbit.B)) if orbit is not None else (False, ({}, {}))


def _run_mu_module(mod: ModuleType, omega: np.ndarray, eps: float, force: float, Q: float,
                   order: int) -> Emitted:
    """A_1, A_3, A_5 of an emitted μ-expansion module at ``omega`` (B_n = 0: undamped), and a
    run over 10⁵ ω through the ``_into`` twins to time."""
    n = omega.size
    A, B = np.zeros((n, 3)), np.zeros((n, 3))  # harmonics the module lacks are zero
    fns = {k: getattr(mod, f"A_{h}_into") for k, h in enumerate((1, 3, 5))
           if hasattr(mod, f"A_{h}_into")}  # the order's harmonics; the rest stay 0
    for k, f in fns.items():
        A[:, k] = f(np.empty(n), omega, eps, force, 0.0)
    dense = np.resize(omega, 100_000)
    buf = np.empty_like(dense)
    return A, B, lambda: [f(buf, dense, eps, force, 0.0) for f in fns.values()], dense.size


def _run_mu_damped_module(mod: ModuleType, omega: np.ndarray, eps: float, force: float,
                          Q: float, order: int) -> Emitted:
    """A_n, B_n (n = 1, 3, 5) of an emitted damped μ-expansion module at ``omega`` on the
    largest branch (NaN outside its verified domain), and a run over 10⁵ ω to time."""
    n = omega.size
    A, B = np.zeros((n, 3)), np.zeros((n, 3))  # harmonics the module lacks are zero
    fns = {(k, c): getattr(mod, f"{c}_{h}_into") for k, h in enumerate((1, 3, 5)) for c in "AB"
           if hasattr(mod, f"{c}_{h}_into")}
    for (k, c), f in fns.items():
        (A if c == "A" else B)[:, k] = f(np.empty(n), omega, eps, force, Q, 0.0)
    dense = np.resize(omega, 100_000)
    buf = np.empty_like(dense)
    return A, B, lambda: [f(buf, dense, eps, force, Q, 0.0) for f in fns.values()], dense.size


def _run_balance_module(mod: ModuleType, omega: np.ndarray, eps: float, force: float, Q: float,
                        order: int) -> Emitted:
    """A_n, B_n of an emitted balance module: its compiled Newton, one solve per ω from the
    one-harmonic root; and a run over every ω to time."""
    n = omega.size
    A, B = np.zeros((n, 3)), np.zeros((n, 3))
    a1, b1 = one_harmonic_amplitudes(eps, force, Q, omega)
    x0 = np.zeros((n, 2 * order))
    x0[:, 0], x0[:, order] = a1, b1
    damping = Drive(eps, force, 1.0, Q).damping
    xs = [mod.newton(x, w, eps, force, damping)[0] for x, w in zip(x0, omega, strict=True)]
    for k in range(min(order, 3)):
        A[:, k] = [x[k] for x in xs]
        B[:, k] = [x[order + k] for x in xs]
    return A, B, lambda: [mod.newton(x, w, eps, force, damping)
                          for x, w in zip(x0, omega, strict=True)], n


def one_harmonic_amplitudes(eps: float, force: float, Q: float,
                            omegas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A₁ = r cos δ₀``, ``B₁ = r sin δ₀`` of the largest one-harmonic branch, vectorised
    (:func:`driven.one_harmonic`)."""
    A, delta = one_harmonic(eps, force, Q, omegas)
    return A[:, 0] * np.cos(delta[:, 0]), A[:, 0] * np.sin(delta[:, 0])


DRIVEN_MAX = 12
# NOTE: μ-orders 0..12 and 1..12 odd harmonics: at the notes' parameters both reach 1e-12
# well before that; more only costs.
SHOOTING_STEPS = (64, 128, 256, 512, 1024)
# NOTE: the "numerical" method: shooting from the one-harmonic guess with plain RK4 at these
# steps per period (the truth uses 4096 and 8192, Richardson-combined).


# --- references ----------------------------------------------------------------------------------

def reference_period(x: np.ndarray) -> np.ndarray:
    """``T/2π = (2/π) K(m)/√(1+x)`` in 30-digit arithmetic (mpmath): the judge of every
    candidate, SciPy's ``ellipk`` included."""
    with mpmath.workdps(30):
        return np.array([float(2 / mpmath.pi * mpmath.ellipk(mpmath.mpf(v) / (2 * (1 + v)))
                               / mpmath.sqrt(1 + mpmath.mpf(v))) for v in x])


QUADRATURE_NODES = 256
# NOTE: Gauss–Legendre nodes in θ (u = m + h sin θ between the turning points): the integrand
# is analytic there for simple turning points, and 256 nodes meet the Duffing oscillator's
# elliptic period to 1e-15 for |x| ≤ 0.9 (tests/test_choose.py).


def quadrature_period(model: Model, x: np.ndarray) -> np.ndarray:
    """``T/2π`` of a free polynomial oscillator at ``y = x`` by quadrature, independent of the
    series: its scaled form ``u'' + u + Σ_k x^k Σ_n c_kn u^n = 0`` (time in units of 1/ω₀,
    ``u(0) = 1``) has the potential ``V(u) = u²/2 + Σ x^k c_kn u^(n+1)/(n+1)``, and
    ``T = 2∫ du/√(2(V(1) − V(u)))`` from the turning point below 1 (the largest root of
    ``V(u) = V(1)`` under 1) up to 1.  NaN where the motion from u = 1 is unbounded (no
    turning point below) or 1 is no turning point."""
    theta, weights = np.polynomial.legendre.leggauss(QUADRATURE_NODES)
    theta, weights = theta * np.pi / 2, weights * np.pi / 2
    out = np.full(x.shape, np.nan)
    for i, xv in enumerate(np.asarray(x, dtype=float)):
        V = np.zeros(2)  # V(u) low to high
        V = np.polynomial.polynomial.polyadd(V, [0.0, 0.0, 0.5])
        for k, terms in enumerate(model.forcing, start=1):
            for n, c in terms:
                coeff = np.zeros(n + 2)
                coeff[n + 1] = float(c) * xv**k / (n + 1)
                V = np.polynomial.polynomial.polyadd(V, coeff)
        dV = np.polynomial.polynomial.polyder(V)
        if np.polynomial.polynomial.polyval(1.0, dV) <= 0:
            continue  # u = 1 is no turning point of a bounded swing
        level = np.polynomial.polynomial.polyval(1.0, V)
        shifted = np.polynomial.polynomial.polysub(V, [level])
        roots = np.polynomial.polynomial.polyroots(shifted)
        below = sorted(r.real for r in roots if abs(r.imag) < 1e-9 and r.real < 1 - 1e-9)
        if not below:
            continue
        u_min = below[-1]
        if np.polynomial.polynomial.polyval(u_min, dV) >= 0:
            continue  # the swing does not turn there: it escapes
        u_min = float(safeguarded(  # Newton polish of the turning point (3 steps)
            lambda _, u, V=shifted, dV=dV: (np.polynomial.polynomial.polyval(u, V),
                                            np.polynomial.polynomial.polyval(u, dV)),
            np.array([u_min]), max_iter=3)[0])
        # V(1) − V(u) = (1 − u)(u − u_min) S(u), and with u = m + h sin θ the product
        # (1 − u)(u − u_min) = h² cos²θ cancels du = h cos θ dθ: T = 2∫ dθ/√(2 S(u)),
        # smooth, with no difference of nearly equal numbers near the turning points
        S, _ = np.polynomial.polynomial.polydiv(
            shifted, np.polynomial.polynomial.polyfromroots([1.0, u_min]))
        u = (1 + u_min) / 2 + (1 - u_min) / 2 * np.sin(theta)
        s_u = np.polynomial.polynomial.polyval(u, S)
        if np.any(s_u <= 0):
            continue  # another turning point between: no swing between these two
        out[i] = 2 * float(np.sum(weights / np.sqrt(2 * s_u))) / (2 * np.pi)
    return out


def reference_q(t: np.ndarray, x: float) -> np.ndarray:
    """``q/A = cn(√(1+x) t | m)``, ``m = x/(2(1+x))``: SciPy for m ≥ 0, mpmath below."""
    m = x / (2 * (1 + x))
    if m >= 0:
        return ellipj(np.sqrt(1 + x) * t, m)[1]
    with mpmath.workdps(20):
        return np.array([float(mpmath.re(mpmath.ellipfun("cn", np.sqrt(1 + x) * v, m)))
                         for v in t])


INTEGRATION_RTOLS = (1e-4, 1e-7, 1e-10, 1e-13)
# NOTE: DOP853 tolerances for the "numerical" method: from plotting accuracy to nearly exact.


def integrated_period(x: float, rtol: float) -> float:
    """``T/2π`` by integrating ``u'' + u + x u³ = 0`` from ``u = 1`` to the half period
    (``u'`` back to zero), SciPy's DOP853 at ``rtol``."""
    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -y[0] - x * y[0] ** 3]

    def half(_t: float, y: np.ndarray) -> float:
        return y[1]

    half.terminal, half.direction = True, 1.0
    sol = solve_ivp(rhs, (0.0, 100.0 / np.sqrt(1 + max(x, 0.0)) + 100.0), [1.0, 0.0],
                    method="DOP853", rtol=rtol, atol=rtol * 1e-3, events=half)
    return float(2 * sol.t_events[0][0] / (2 * np.pi))
