"""One equation's response curve before it is traced: the one-harmonic balance of any
polynomial force, its amplitudes and folds, the ω range, the continuation's estimate, the
equation lowered for a curve in ω, the seeds at one ω (§10.4).

Eq. 10.60, ``q̈ + q̇/Q + q + εq³ = f cos ωt``: at one harmonic ``r²[(1 − ω² + ¾εr²)² +
ω²/Q²] = f²`` is a cubic ``G(u) = 0`` in ``u = r²``.  A branch is stable where ``∂G/∂u > 0``
(the slow flow of ``a, b`` has a saddle where it is negative, between the folds); the folds
solve ``G = ∂G/∂u = 0``.  The curve traced: :func:`systems.response`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np
import sympy as sp

from ..errors import InputError
from ..numerics.newton import DIFFERENCE_STEP, newton, safeguarded
from .continuation import MAX_POINTS, drive_crossings
from .driven import (
    Drive,
    amplitude_residual,
    amplitude_slope,
    one_harmonic_roots,
)
from .polynomial import DrivenEquation, PolynomialBalance

_u, _w, _e, _f, _g = sp.symbols("u w e f g")  # u = r², w = ω², g = 1/Q
_G = _u * ((1 - _w + sp.Rational(3, 4) * _e * _u) ** 2 + _w * _g**2) - _f**2


@functools.cache
def _fold_polynomial() -> sp.Poly:
    """The resultant in u of G and ∂G/∂u (the cubic's discriminant), a polynomial in ω² whose
    positive roots with a positive double root u are the folds; derived once, on first use."""
    return sp.Poly(sp.resultant(_G, sp.diff(_G, _u), _u), _w)


@dataclass(frozen=True)
class ResponseCurve:
    """One-harmonic amplitudes ``r`` (NaN where a branch does not exist), largest first."""

    omega: np.ndarray  # (n,)
    r: np.ndarray  # (n, 3)
    stable: np.ndarray  # (n, 3) bool


def one_harmonic_curve(eps: float, force: float, Q: float, omega: np.ndarray) -> ResponseCurve:
    """All real branches of the amplitude equation over ``omega``, vectorised
    (:func:`driven.one_harmonic_roots`)."""
    d = Drive(eps, force, 1.0, Q)
    w = np.asarray(omega, dtype=float)
    if np.any(~np.isfinite(w)) or np.any(w <= 0):
        raise InputError("omega: every frequency must be finite and > 0")
    roots = one_harmonic_roots(eps, force, Q, w)
    r = np.sqrt(roots)
    with np.errstate(invalid="ignore"):
        stable = amplitude_slope(roots, w[:, None], d) > 0
    return ResponseCurve(w, r, stable & np.isfinite(r))


def one_harmonic_folds(eps: float, force: float, Q: float) -> list[float]:
    """Fold frequencies (ascending) to full double precision: ``G = ∂G/∂u = 0``.

    Candidates from the roots in ω² of the discriminant, polished by Newton's method on the
    2×2 system in ``(u, ω)``.
    """
    d = Drive(eps, force, 1.0, Q)
    if eps == 0:
        return []
    values = {_e: eps, _f: force, _g: d.damping}
    # SymPy's floats do not overflow: scale by the largest coefficient before rounding to
    # float64 (ε = 1e100 puts ε⁴f² far beyond 1e308, yet the roots in ω² are ordinary)
    exact = [sp.Float(c.subs(values), 30) for c in _fold_polynomial().all_coeffs()]
    scale = max(abs(c) for c in exact)
    coeffs = [float(c / scale) for c in exact] if scale != 0 else []
    if not coeffs or not all(np.isfinite(coeffs)):
        raise InputError(f"eps {eps:g}, force {force:g}, Q {Q:g}: the fold polynomial's "
                         "coefficients leave double precision")
    folds = []
    for w2 in np.roots(coeffs):
        if abs(w2.imag) > 1e-8 * (1 + abs(w2)) or w2.real <= 0:
            continue
        omega = float(np.sqrt(w2.real))
        # the double root u of the cubic: ∂G/∂u = 0 is quadratic in u
        a = 1 - omega**2
        us = np.roots([27 / 16 * eps**2, 3 * eps * a, a * a + omega**2 * d.damping**2])
        us = [float(x.real) for x in us if abs(x.imag) < 1e-8 * (1 + abs(x)) and x.real > 0]
        if not us:
            continue
        u = min(us, key=lambda x: abs(amplitude_residual(x, omega, d)))

        def system(z: np.ndarray) -> np.ndarray:
            return np.array([amplitude_residual(z[0], z[1], d), amplitude_slope(z[0], z[1], d)])

        def jacobian(z: np.ndarray) -> np.ndarray:
            u, w = z
            A = 1 - w**2 + 0.75 * eps * u
            Gw = u * (-4 * w * A + 2 * w * d.damping**2)
            Guu = 2 * A * 0.75 * eps + 1.5 * eps * A + 1.5 * eps * u * 0.75 * eps
            Guw = 2 * A * (-2 * w) + 2 * w * d.damping**2 + 1.5 * eps * u * (-2 * w)
            return np.array([[amplitude_slope(u, w, d), Gw], [Guu, Guw]])

        # singular (a cusp, or the scale of u swamps ω): Newton stops, the check below judges
        (u, omega), _, _ = newton(system, jacobian, np.array([u, omega]), 1e-15, 20)
        if u > 0 and abs(amplitude_residual(u, omega, d)) < 1e-9 * (1 + force**2):
            folds.append(float(omega))
    return sorted({float(w) for w in folds})


def response_range(eps: float, force: float, Q: float, omega_min: float | None = None,
                   omega_max: float | None = None) -> tuple[float, float]:
    """The ω range a response curve is drawn on: half the lowest to 1.25 × the highest of
    ω = 1 and the one-harmonic folds, each end replaced by ``omega_min``/``omega_max`` where
    given (:func:`given_range`)."""
    folds = one_harmonic_folds(eps, force, Q)
    return given_range(0.5 * min([1.0, *folds]), 1.25 * max([1.0, *folds]), omega_min,
                       omega_max)


def given_range(lo: float, hi: float, omega_min: float | None,
                omega_max: float | None) -> tuple[float, float]:
    """``(lo, hi)`` with each end replaced by ``--omega A:B``'s where given, checked: finite,
    > 0 and A below B (one line naming the flag otherwise)."""
    lo = lo if omega_min is None else omega_min
    hi = hi if omega_max is None else omega_max
    for flag, value in (("--omega A", lo), ("--omega B", hi)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{flag} = {value!r}: must be finite and > 0")
    if not lo < hi:
        raise InputError(f"--omega {lo:g}:{hi:g}: A must lie below B")
    return lo, hi


_poly = np.polynomial.polynomial

@dataclass(frozen=True)
class OneHarmonic:
    """``q = r cos(ωt − φ)`` in ``q̈ + g(q, q̇) = f cos ωt`` (a polynomial ``g``, its table
    ``terms``): the first harmonic of ``q̈ + g`` is ``(P_c(r), P_s(r))`` with
    ``P_c = −ω²r + Σ c ω^b C_ab r^(a+b)``, ``P_s = Σ c ω^b S_ab r^(a+b)`` (``C_ab``, ``S_ab``
    the cos θ, sin θ coefficients of ``cos^a θ (−sin θ)^b``), and ``H(r) = P_c² + P_s² − f²``
    vanishes at the amplitudes: for eq. 10.60 exactly the cubic ``G`` of the module's header
    (in ``r``), so the same folds."""

    terms: dict[tuple[int, int], float]
    force: float

    @functools.cached_property
    def _harmonics(self) -> list[tuple[int, int, float, float, float]]:
        theta = 2 * np.pi * np.arange(64) / 64
        out = []
        for (a, b), c in sorted(self.terms.items()):
            wave = np.cos(theta) ** a * (-np.sin(theta)) ** b
            out.append((a, b, c, 2 * float(np.mean(wave * np.cos(theta))),
                        2 * float(np.mean(wave * np.sin(theta)))))
        return out

    def polynomial(self, omega: float) -> np.ndarray:
        """``H(r)`` at ``omega``: its coefficients, lowest power first, trimmed."""
        d = max(a + b for a, b, *_ in self._harmonics)
        pc, ps = np.zeros(d + 1), np.zeros(d + 1)
        pc[1] = -omega**2
        for a, b, c, cos, sin in self._harmonics:
            pc[a + b] += c * omega**b * cos
            ps[a + b] += c * omega**b * sin
        H = _poly.polyadd(_poly.polymul(pc, pc), _poly.polymul(ps, ps))
        H[0] -= self.force**2
        return _poly.polytrim(H, 0)

    def amplitudes(self, omega: float) -> np.ndarray:
        """The positive real roots r of ``H``, ascending (each polished by Newton's method,
        :func:`numerics.newton.safeguarded`)."""
        H = self.polynomial(omega)
        dH = _poly.polyder(H)
        roots = _poly.polyroots(H)
        scale = 1 + np.abs(roots)
        rs = roots.real[(np.abs(roots.imag) <= 1e-7 * scale) & (roots.real > 0)]

        def value_slope(i: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return _poly.polyval(r, H), _poly.polyval(r, dH)

        rs = safeguarded(value_slope, rs, max_iter=3)  # unbracketed: at most three steps
        return np.sort(rs[rs > 0])

    def phase(self, r: float, omega: float) -> float:
        """φ of the root ``r``: ``(P_c, P_s) = f (cos φ, −sin φ)``."""
        pc = -omega**2 * r + sum(c * omega**b * cos * r ** (a + b)
                                 for a, b, c, cos, _ in self._harmonics)
        ps = sum(c * omega**b * sin * r ** (a + b) for a, b, c, _, sin in self._harmonics)
        return math.atan2(-ps, pc)

    def folds(self, lo: float, hi: float, points: int = 1500) -> list[float]:
        """The ω in ``[lo, hi]`` where two amplitudes meet (``H = ∂H/∂r = 0``): where the
        number of roots changes on a geometric grid, each polished by Newton's method in
        ``(r, ω)`` from the closest pair at the grid point that has it.  Two folds within one
        step of the grid (0.3 % of ω) are not told apart."""
        grid = np.geomspace(lo, hi, points)
        counts = [len(self.amplitudes(w)) for w in grid]
        out = []
        for i in range(points - 1):
            if counts[i] == counts[i + 1]:
                continue
            j = i if counts[i] > counts[i + 1] else i + 1  # the side with the pair
            rs = self.amplitudes(grid[j])
            if len(rs) < 2:
                continue
            k = int(np.argmin(np.diff(rs)))
            fold = self._polish_fold(np.array([0.5 * (rs[k] + rs[k + 1]), grid[j]]))
            if fold is not None and grid[i] * (1 - 1e-3) <= fold <= grid[i + 1] * (1 + 1e-3):
                out.append(fold)
        return sorted(out)

    def _polish_fold(self, z: np.ndarray) -> float | None:
        """``H = ∂H/∂r = 0`` by Newton's method in ``(r, ω)`` from ``z``, exact in r (H is a
        polynomial), a central difference in ω: its ω, or ``None`` where Newton leaves
        ``r, ω > 0`` or overflows.  (Differences in r as well let a start beside a fold at
        r ≈ 14 leap to another fold: eq. 10.60 at Q = 185 lost its upper fold, ω = 3.963.)"""
        def F(z: np.ndarray) -> np.ndarray:
            if not (z[0] > 0 and z[1] > 0):
                return np.full(2, np.nan)
            H = self.polynomial(z[1])
            return np.array([_poly.polyval(z[0], H), _poly.polyval(z[0], _poly.polyder(H))])

        def J(z: np.ndarray) -> np.ndarray:
            r, w = z
            H, h = self.polynomial(w), DIFFERENCE_STEP * w
            Hw = _poly.polysub(self.polynomial(w + h), self.polynomial(w - h)) / (2 * h)
            dH = _poly.polyder(H)
            return np.array([[_poly.polyval(r, dH), _poly.polyval(r, Hw)],
                             [_poly.polyval(r, _poly.polyder(dH)),
                              _poly.polyval(r, _poly.polyder(Hw))]])

        z, _, _ = newton(F, J, z, 1e-15, 40)
        return float(z[1]) if np.all(np.isfinite(z)) and z[0] > 0 and z[1] > 0 else None

    def extent(self, lo: float, hi: float, folds: list[float]) -> float:
        """The largest amplitude on ``[lo, hi]`` (a grid and the folds)."""
        grid = np.concatenate([np.linspace(lo, hi, 400), folds])
        return float(max((r for w in grid for r in self.amplitudes(w)), default=0.0))


EQUATION_POINT_SECONDS = (2e-3, 1e-6)
# NOTE: seconds per continuation point of a user's equation, fixed + per unknown²: the
# alternating frequency/time Jacobian (S samples × m unknowns, S ≈ 2(d + 1)·2N) and the SVD;
# measured 2.5 ms at m = 31 (N = 8, a force with even terms), 16 ms at m = 127 (N = 32).


def equation_point_seconds(unknowns: int) -> float:
    """Estimated seconds of one continuation point of a user's equation with ``unknowns``
    unknowns (:data:`EQUATION_POINT_SECONDS`: fixed, plus per unknown²)."""
    return EQUATION_POINT_SECONDS[0] + EQUATION_POINT_SECONDS[1] * unknowns**2


@dataclass(frozen=True)
class EquationResponse:
    """What ``lindstedt response EQUATION`` computes before its sweeps."""

    one_harmonic: OneHarmonic
    omega_range: tuple[float, float]
    one_harmonic_folds: list[float]
    linear_frequency: float


def linear_frequency(terms: dict[tuple[int, int], float]) -> float:
    """``ω₀ = √c`` of the linear term ``c q``; :class:`InputError` where ``c ≤ 0``."""
    c = terms.get((1, 0), 0.0)
    if not c > 0:
        raise InputError(f"the linear term {c:g}*q: no oscillation about q = 0 (ω0² must be "
                         "> 0) to draw a response curve around")
    return math.sqrt(c)


def equation_range(terms: dict[tuple[int, int], float], force: float,
                   omega_min: float | None = None,
                   omega_max: float | None = None) -> EquationResponse:
    """The ω range of a response curve: as for eq. 10.60, half the lowest to 1.25 × the highest
    of ω₀ and the one-harmonic folds (looked for in ``[ω₀/10, 10ω₀]``), each end replaced by
    ``omega_min``/``omega_max`` where given."""
    w0 = linear_frequency(terms)
    one = OneHarmonic(dict(terms), float(force))
    folds = one.folds(0.1 * w0, 10 * w0)
    lo, hi = given_range(0.5 * min([w0, *folds]), 1.25 * max([w0, *folds]), omega_min,
                         omega_max)
    return EquationResponse(one, (lo, hi), [w for w in folds if lo <= w <= hi], w0)


def equation_continuation_seconds(terms: dict[tuple[int, int], float], force: float,
                                  harmonics: int, odd: bool, lo: float, hi: float,
                                  step: float = 0.02, max_points: int = MAX_POINTS,
                                  where: str | None = None) -> tuple[float, float]:
    """``(points, seconds)`` the continuation of :func:`continue_equation` is estimated at (its
    length ``(hi − lo) + π r_max`` over ``step``, r_max from the one-harmonic amplitudes), or
    :class:`InputError` above ``max_points``."""
    one = OneHarmonic(dict(terms), float(force))
    r_max = one.extent(lo, hi, one.folds(lo, hi, 400))
    estimate = ((hi - lo) + np.pi * r_max) / step
    if not estimate <= max_points:
        where = f"force {force:g}" if where is None else where
        raise InputError(f"{where}: the response curve spans ω in [{lo:.3g}, {hi:.3g}] "
                         f"with one-harmonic amplitudes up to {r_max:.3g}, about "
                         f"{estimate:.2g} continuation steps of {step:g}; the limit is "
                         f"{max_points}")
    unknowns = 2 * harmonics if odd else 4 * harmonics - 1
    # the ends: two continuations in the drive amplitude, each within its own deadline
    return estimate, estimate * equation_point_seconds(unknowns)


def equation_solutions(de: DrivenEquation, fine: PolynomialBalance, omega: float
                       ) -> tuple[list[np.ndarray], bool]:
    """Every balance solution at ``omega`` that the continuation in the drive amplitude from
    rest crosses (at most CONTINUATION_HARMONICS harmonics, then Newton at ``fine``'s), distinct,
    by amplitude; and whether that continuation was complete and every crossing converged."""
    coarse, seeds, curve = drive_crossings(replace(de, omega=omega), fine.harmonics)
    return polished(coarse, seeds, curve.complete, fine, omega)


def polished(coarse: PolynomialBalance, seeds: list[np.ndarray], complete: bool,
             fine: PolynomialBalance, omega: float) -> tuple[list[np.ndarray], bool]:
    """The ``seeds`` of ``coarse`` polished by Newton at ``fine``'s harmonics, distinct, by
    first-harmonic size; ``complete`` and whether every seed converged."""
    out: list[np.ndarray] = []
    for x in seeds:
        xb, converged, _ = fine.solve(fine.refined(coarse, x), omega)
        if not converged:
            complete = False
            continue
        if all(np.linalg.norm(y - xb) > 1e-6 * (1 + np.linalg.norm(xb)) for y in out):
            out.append(xb)
    out.sort(key=fine.first_harmonic)
    return out, complete


ESCAPE_FACTOR = 10.0
# NOTE: a user's equation has no barrier in closed form: a sweep whose |q| passes 10× the largest
# |q| of any balance solution on the range (Σ|a_k| + |b_k| over the continued curve), moving
# outward, has left every steady state there: an escape (a softening spring over its barrier
# runs off to infinity within a period or two after that).

RESPONSE = "response"


def response_equation(text: str, values: dict[str, str], name: str = "oscillator",
                      method: str = RESPONSE) -> DrivenEquation:
    """A user's damped driven oscillator for a response curve in its drive frequency: the
    :class:`driven.DrivenEquation` of ``text`` (ω left free: every parameter but the drive
    frequency needs a value), refused in one line where the force depends on the drive
    frequency or has no damping (a term odd in q')."""
    from .polynomial import driven_equation

    def lowered(omega: float) -> DrivenEquation:
        try:
            return driven_equation(text, values, omega, name)
        except InputError as exc:
            message = str(exc).replace(": driven does not apply: ", f": {method} does not apply: ")
            message = message.replace("(its value is --omega)", f"(the {method} curve's ω)")
            if " is the drive frequency; give it with --omega" in message:
                message = message.split(";")[0] + f"; {method} varies it (drop this --param)"
            raise InputError(message) from None

    de, other = lowered(1.0), lowered(2.0)
    if de.terms != other.terms or de.force != other.force:
        raise InputError(f"{name} ({text}): {method} does not apply: the force or the drive's "
                         f"amplitude depends on the drive frequency {de.frequency}, which the "
                         "curve varies")
    if not de.dissipative:
        raise InputError(f"{name} ({text}): {method} does not apply: no damping (a term odd in "
                         "the velocity, e.g. q'/Q): no steady state to draw a response curve of")
    linear_frequency(de.terms)
    return de
