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
from fractions import Fraction

import flint
import numpy as np

from ..errors import InputError
from ..numerics.newton import newton, safeguarded
from .continuation import MAX_POINTS, drive_crossings
from .driven import Drive, amplitude_slope, one_harmonic_roots
from .polynomial import DrivenEquation, PolynomialBalance


@dataclass(frozen=True)
class ResponseCurve:
    """One-harmonic amplitudes ``r`` (NaN where a branch does not exist), largest first, and
    whether ``∂G/∂u > 0`` there (the notes' stability of the slow flow's fixed point)."""

    omega: np.ndarray  # (n,)
    r: np.ndarray  # (n, branches)
    stable: np.ndarray  # (n, branches) bool


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


def first_harmonic(a: int, b: int) -> tuple[Fraction, Fraction]:
    """``(C_ab, S_ab)``: the cos θ and sin θ coefficients of ``cos^a θ (−sin θ)^b``, exact.

    With ``z = e^{iθ}``, ``cos^a θ (−sin θ)^b = i^b (z + 1/z)^a (z − 1/z)^b / 2^(a+b)``; the
    coefficient of ``z`` in the product of the binomials is ``K = Σ_k C(a, n − k) C(b, k)
    (−1)^k``, ``n = (a + b − 1)/2``, so an even ``a + b`` has no first harmonic, an even
    ``b`` gives ``C = (−1)^(b/2) K/2^(a+b−1)`` and an odd one ``S = −(−1)^((b−1)/2)
    K/2^(a+b−1)``.

    >>> first_harmonic(3, 0), first_harmonic(0, 1)  # ¾ q³ on cos θ; q̇ = −ω r sin θ
    ((Fraction(3, 4), Fraction(0, 1)), (Fraction(0, 1), Fraction(-1, 1)))
    """
    if (a + b) % 2 == 0:
        return Fraction(0), Fraction(0)
    n = (a + b - 1) // 2
    K = sum(math.comb(a, n - k) * math.comb(b, k) * (-1) ** k for k in range(b + 1)
            if 0 <= n - k <= a)
    size = Fraction(K, 2 ** (a + b - 1))
    if b % 2 == 0:
        return (-1) ** (b // 2) * size, Fraction(0)
    return Fraction(0), -((-1) ** ((b - 1) // 2)) * size


_poly = np.polynomial.polynomial


@dataclass(frozen=True)
class OneHarmonic:
    """``q = r cos(ωt − φ)`` in ``q̈ + g(q, q̇) = f cos ωt`` (a polynomial ``g``, its table
    ``terms``): the first harmonic of ``q̈ + g`` is ``(P_c, P_s)`` with ``P_c = −ω²r + Σ c ω^b
    C_ab r^(a+b)``, ``P_s = Σ c ω^b S_ab r^(a+b)`` (:func:`first_harmonic`: only odd ``a + b``
    contribute, ``P_c`` even ``b``, ``P_s`` odd ``b``), so that ``P_c = r p_c(u, w)``,
    ``P_s = rω p_s(u, w)`` in ``u = r²``, ``w = ω²``, and the amplitudes are the roots of
    ``G(u, w) = u (p_c² + w p_s²) − f²``, a polynomial in both: for eq. 10.60 exactly the
    cubic ``r²[(1 − ω² + ¾εr²)² + ω²/Q²] = f²`` (§10.4)."""

    terms: dict[tuple[int, int], float]
    force: float

    @functools.cached_property
    def _harmonics(self) -> list[tuple[int, int, float, float, float]]:
        out = []
        for (a, b), c in sorted(self.terms.items()):
            cos, sin = first_harmonic(a, b)
            out.append((a, b, c, float(cos), float(sin)))
        return out

    def polynomial(self, omega: float) -> np.ndarray:
        """``H(r) = P_c² + P_s² − f²`` at ``omega``: its coefficients, lowest power first,
        trimmed."""
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

    def curve(self, omega: np.ndarray) -> ResponseCurve:
        """Every amplitude at each of ``omega`` (:meth:`amplitudes`), largest first, with
        ``∂G/∂u > 0`` (``H'(r) = 2r ∂G/∂u``: the sign of ``H'`` at the root)."""
        roots = [self.amplitudes(float(w))[::-1] for w in omega]
        width = max((len(rs) for rs in roots), default=0)
        r = np.full((len(roots), width), np.nan)
        stable = np.zeros((len(roots), width), dtype=bool)
        for i, (w, rs) in enumerate(zip(omega, roots, strict=True)):
            r[i, :len(rs)] = rs
            stable[i, :len(rs)] = _poly.polyval(rs, _poly.polyder(self.polynomial(w))) > 0
        return ResponseCurve(np.asarray(omega, dtype=float), r, stable)

    @functools.cached_property
    def _amplitude_polynomials(self) -> tuple[flint.fmpq_mpoly, flint.fmpq_mpoly]:
        """``p_c(u, w)`` and ``p_s(u, w)``, exact: the terms' floats as the rationals they
        are."""
        ctx = flint.fmpq_mpoly_ctx.get(("u", "w"), "lex")
        u, w = ctx.gens()
        pc, ps = -w, ctx.constant(0)
        for (a, b), c in sorted(self.terms.items()):
            cos, sin = first_harmonic(a, b)
            term = _rational(Fraction(c)) * u ** ((a + b - 1) // 2)
            if cos:
                pc += _rational(cos) * term * w ** (b // 2)
            if sin:
                ps += _rational(sin) * term * w ** ((b - 1) // 2)
        return pc, ps

    @functools.cached_property
    def folds(self) -> tuple[float, ...]:
        """Every ω > 0 where two amplitudes meet, ascending: ``G = ∂G/∂u = 0``.  Candidates are
        the positive roots in ``w = ω²`` of the resultant in ``u`` of ``G`` and ``∂G/∂u``
        (exact, FLINT; for eq. 10.60 the cubic's discriminant), each with its double root
        ``u > 0`` (the root of ``∂G/∂u`` where ``|G|`` is least), polished by Newton's method
        in ``(u, ω)`` (:func:`numerics.newton.newton`) on ``G`` written as ``u (p_c² +
        ω² p_s²) − f²`` (``p_c`` holds ``ω0² − ω²``: no cancellation of large terms near a
        fold far up a resonance)."""
        pc, ps = self._amplitude_polynomials
        u_, w_ = pc.context().gens()
        G = u_ * (pc * pc + w_ * ps * ps) - _rational(Fraction(self.force)) ** 2
        R = G.resultant(G.derivative("u"), "u").to_dict()
        top = max((j for _, j in R), default=0)
        exact = [R.get((0, j), flint.fmpq(0)) for j in range(top, -1, -1)]
        scale = max(abs(c) for c in exact)
        if top == 0 or scale == 0:
            return ()
        # the exact coefficients scaled before rounding: ε = 1e100 puts ε⁴f² beyond 1e308
        coeffs = [float(c / scale) for c in exact]
        slope_u = _array(G.derivative("u"))
        C, S = _array(pc), _array(ps)
        parts = [(A, _poly.polyder(A, axis=0), _poly.polyder(A, axis=1),
                  _poly.polyder(A, 2, axis=0), _poly.polyder(_poly.polyder(A, axis=0), axis=1))
                 for A in (C, S)]
        f2 = self.force**2

        def values(z: np.ndarray) -> tuple[float, ...]:
            """G, G_u, G_ω, G_uu, G_uω at ``z = (u, ω)``."""
            u, om = z
            w = om * om
            (P, Pu, Pw, Puu, Puw), (T, Tu, Tw, Tuu, Tuw) = (
                [float(_poly.polyval2d(u, w, A)) for A in part] for part in parts)
            Pw, Puw, Tw, Tuw = 2 * om * Pw, 2 * om * Puw, 2 * om * Tw, 2 * om * Tuw  # d/dω
            inner = P * P + w * T * T
            inner_u = 2 * P * Pu + 2 * w * T * Tu
            inner_w = 2 * P * Pw + 2 * om * T * T + 2 * w * T * Tw
            inner_uu = 2 * Pu * Pu + 2 * P * Puu + 2 * w * (Tu * Tu + T * Tuu)
            inner_uw = (2 * Pw * Pu + 2 * P * Puw + 4 * om * T * Tu
                        + 2 * w * (Tw * Tu + T * Tuw))
            return (u * inner - f2, inner + u * inner_u, u * inner_w, 2 * inner_u + u * inner_uu,
                    inner_w + u * inner_uw)

        def system(z: np.ndarray) -> np.ndarray:
            return np.array(values(z)[:2])

        def jacobian(z: np.ndarray) -> np.ndarray:
            _, Gu, Gw, Guu, Guw = values(z)
            return np.array([[Gu, Gw], [Guu, Guw]])

        out: list[float] = []
        with np.errstate(over="ignore", invalid="ignore"):
            for w2 in np.roots(coeffs):
                if abs(w2.imag) > 1e-8 * (1 + abs(w2)) or w2.real <= 0:
                    continue
                omega = math.sqrt(w2.real)
                slope = _poly.polytrim(_poly.polyval(w2.real, slope_u.T), 0)  # ∂G/∂u in u
                if len(slope) < 2:
                    continue
                us = [x.real for x in _poly.polyroots(slope)
                      if abs(x.imag) < 1e-8 * (1 + abs(x)) and x.real > 0]
                if not us:
                    continue
                u = min(us, key=lambda x: abs(values((x, omega))[0]))
                # singular (a cusp, or the scale of u swamps ω): Newton stops, the check judges
                (u, omega), _, _ = newton(system, jacobian, np.array([u, omega]), 1e-15, 20)
                if u > 0 and omega > 0 and abs(values((u, omega))[0]) < 1e-9 * (1 + f2):
                    out.append(float(omega))
        folds: list[float] = []
        for w in sorted(out):
            if not folds or w - folds[-1] > 1e-12 * w:
                folds.append(w)
        return tuple(folds)

    def extent(self, lo: float, hi: float) -> float:
        """The largest amplitude on ``[lo, hi]`` (a grid and the folds in it)."""
        grid = np.concatenate([np.linspace(lo, hi, 400),
                               [w for w in self.folds if lo <= w <= hi]])
        return float(max((r for w in grid for r in self.amplitudes(w)), default=0.0))


def _rational(x: Fraction) -> flint.fmpq:
    return flint.fmpq(x.numerator, x.denominator)


def _array(p: flint.fmpq_mpoly) -> np.ndarray:
    """The coefficients of ``p(u, w)`` as floats, ``[i, j]`` of ``u^i w^j``."""
    terms = p.to_dict()
    out = np.zeros((1 + max((i for i, _ in terms), default=0),
                    1 + max((j for _, j in terms), default=0)))
    for (i, j), c in terms.items():
        out[i, j] = float(c)
    return out


EQUATION_POINT_SECONDS = (2e-3, 1e-6)
# NOTE: seconds per continuation point of a user's equation, fixed + per unknown²: the
# alternating frequency/time Jacobian (S samples × m unknowns, S ≈ 2(d + 1)·2N) and the SVD;
# measured 2.5 ms at m = 31 (N = 8, a force with even terms), 16 ms at m = 127 (N = 32).


def equation_point_seconds(unknowns: int) -> float:
    """Estimated seconds of one continuation point of a user's equation with ``unknowns``
    unknowns (:data:`EQUATION_POINT_SECONDS`: fixed, plus per unknown²)."""
    return EQUATION_POINT_SECONDS[0] + EQUATION_POINT_SECONDS[1] * unknowns**2


@dataclass(frozen=True)
class ResponseRange:
    """The ω range of one equation's response curve: its one-harmonic balance, the range, the
    one-harmonic folds in it and the linear ω0."""

    one_harmonic: OneHarmonic
    omega_range: tuple[float, float]
    one_harmonic_folds: tuple[float, ...]
    linear_frequency: float


def linear_frequency(terms: dict[tuple[int, int], float]) -> float:
    """``ω₀ = √c`` of the linear term ``c q``; :class:`InputError` where ``c ≤ 0``."""
    c = terms.get((1, 0), 0.0)
    if not c > 0:
        raise InputError(f"the linear term {c:g}*q: no oscillation about q = 0 (ω0² must be "
                         "> 0) to draw a response curve around")
    return math.sqrt(c)


def response_range(terms: dict[tuple[int, int], float], force: float,
                   omega_min: float | None = None,
                   omega_max: float | None = None) -> ResponseRange:
    """The ω range of a response curve: half the lowest to 1.25 × the highest of ω₀ and the
    one-harmonic folds (:attr:`OneHarmonic.folds`), each end replaced by
    ``omega_min``/``omega_max`` where given (:func:`given_range`)."""
    w0 = linear_frequency(terms)
    one = OneHarmonic(dict(terms), float(force))
    folds = one.folds
    lo, hi = given_range(0.5 * min([w0, *folds]), 1.25 * max([w0, *folds]), omega_min,
                         omega_max)
    return ResponseRange(one, (lo, hi), tuple(w for w in folds if lo <= w <= hi), w0)


def equation_continuation_seconds(terms: dict[tuple[int, int], float], force: float,
                                  harmonics: int, odd: bool, lo: float, hi: float,
                                  step: float = 0.02, max_points: int = MAX_POINTS,
                                  where: str | None = None) -> tuple[float, float]:
    """``(points, seconds)`` one equation's continuation (:func:`analysis.systems.
    continue_balance`) is estimated at (its length ``(hi − lo) + π r_max`` over ``step``,
    r_max from the one-harmonic amplitudes), or :class:`InputError` above ``max_points``."""
    r_max = OneHarmonic(dict(terms), float(force)).extent(lo, hi)
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
