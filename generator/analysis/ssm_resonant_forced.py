"""The forced response of two modes in internal resonance from their 4-D SSM
(:mod:`analysis.ssm_resonant`): the drive ``F cos Ωt`` at leading order (order 0 in p), the
steady states of the reduced polynomial system traced in Ω by the package's one
pseudo-arclength continuation (:func:`analysis.continuation._continue`), each with its
stability and each output's physical amplitude.

**The drive.**  Near ``Ω ≈ κ ω₁`` (``κ = 1``, or ``κ = r`` near the upper mode) the drive's
``e^{iΩt}`` is resonant with the directions ``j`` of ``ν_j = κ``: the order-0 homological
equation ``L(iΩ) X + Σ_j ((iΩ + Λ_j)M + C) Φ_j a_j = F/2``, bordered as every resonant row by
``w_jᵀ(C + (Λ_j + iΩ)M) X + Σ_l (w_jᵀ M Φ_l) a_l = 0``, gives the forcing ``a_j`` of the
reduced dynamics and the manifold's forced part ``x ∋ X e^{iΩt} + c.c.``:
``p_k' = R_k(p) + a_k e^{iΩt}`` (``a_k = 0`` where ``ν_k ≠ κ``).

**Steady states.**  In the frame ``p_k = u_k e^{iν_kφ}``, ``φ = Ωt/κ``, every kept monomial
``p^m`` of ``p_k'`` turns into ``u^m e^{iν_kφ}`` (``m·ν = ν_k``), so

    u_k' = (λ_k − iν_kΩ/κ) u_k + Σ_m R_{k,m} u^m + a_k(Ω) = 0

is autonomous: four real equations in ``(Re u₁, Im u₁, Re u₂, Im u₂)``, continued in Ω from the
linear response at both ends of the range through its folds, and from every branch point on
that curve (``det ∂R/∂x`` changes sign with no fold: the branch it crosses, e.g. the coupled
branch born where a drive near the upper mode saturates).  A state is stable where every
eigenvalue of the 4 × 4 Jacobian has a negative real part.  Its motion ``x(φ)`` has the
harmonics ``h = m·ν`` of ``W_m u^m`` and ``±κ`` of ``X``; the amplitude is ``max |x_i|`` over a
period ``2πκ/Ω`` (:func:`analysis.ssm.peak_amplitude`).  A subharmonic state (κ > 1) recurs
κ times (``u₁`` turned by ``2π/κ``: the same motion a drive period later); one is kept.
Isolas (branches that reach neither an end of the range nor a branch point of the traced
curve) are not sought."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sparse
from numpy.polynomial import chebyshev

from ..derive.system import System
from ..errors import InputError
from ..numerics.newton import secant
from .ssm import BORDERED, DENSE_SOLVES, _bordered, _damping, leading, peak_amplitude
from .ssm_forced import BACKBONE_POINTS, DEFAULT_SPAN, NAMED_OUTPUTS, REACH
from .ssm_resonant import ResonantSSM, Term, resonant_ssm

if TYPE_CHECKING:
    from .continuation import Continuation

STEPS = 50
# NOTE: the continuation's step is the range over this many (in (u, Ω), u of order ρ): a
# resonance of Q ~ 50 over a ±20 % range is crossed in ~10 steps, halved where it turns.
POINT_SECONDS = 2e-4
# NOTE: the continuation's cost per point for its point bound (a 4 × 4 system: ~0.1 ms).
MAX_POINTS = 20000
DIFFERENCE = 1e-7
# NOTE: the relative step in Ω of the drive's a_k(Ω) central difference (its derivative).
SAME = 1e-9
# NOTE: folds of the κ copies of a subharmonic branch agree to rounding; one is reported; and
# |u₁| below this fraction of the largest unknown is the plane u₁ = 0 (kept whatever its angle).
CHEBYSHEV_NODES = 16
CHEBYSHEV_MOST = 256
INTERPOLATED = 1e-12
# NOTE: a(Ω) is smooth over a range that holds no eigenvalue it is not bordered against: 16
# nodes reach 1e-12 (relative) over ±20 % of a 2-DOF pair's mode; 256 is a bound, not a need.


@dataclass(frozen=True)
class PairState:
    """One steady state: ``omega`` (Ω), ``u`` (``p_k = u_k e^{iν_kφ}``), ``rho`` (``|u_k|``),
    each output's ``amplitude`` (max |x_i| over a period), ``stable``, the full state
    ``(x, x')`` at ``t = 0`` (``W(u) + 2 Re X``, ``V(u) + 2 Re(iΩX)``) and ``rate``, the
    largest real part of the reduced Jacobian's eigenvalues (a perturbation grows or decays
    as ``e^{rate·t}``; stable where negative)."""

    omega: float
    u: tuple[complex, complex]
    rho: tuple[float, float]
    amplitude: np.ndarray = field(repr=False)
    stable: bool
    start: np.ndarray = field(repr=False)  # (x(0), x'(0)) of the motion, t = 0
    rate: float = 0.0  # the largest real part of the Jacobian's eigenvalues


@dataclass(frozen=True)
class PairResponse:
    """The traced steady states inside the radius in order along the curve (``pieces``: each
    piece's first index; ``beyond``: how many past the radius were dropped), the folds in Ω
    (inside the radius), the drive's resonant mode (``kappa``: Ω ≈ κω₁) and forcing ``a_k`` at
    the range's middle."""

    kappa: int
    states: tuple[PairState, ...]
    pieces: tuple[int, ...]
    folds: tuple[float, ...]
    forcing: tuple[complex, complex]
    beyond: int = 0  # traced states past the radius (max |u_k| > radius), dropped


class _Drive:
    """The order-0 forced terms at Ω, each solved once: ``(a, X)``, ``a`` the forcing of
    ``(p₁', p₂')``, ``X`` the manifold's forced part."""

    def __init__(self, model: ResonantSSM, kappa: int) -> None:
        w = model.matrices
        if w.drive is None:
            raise InputError("the system is not driven: no forced response (drive one equation "
                             "with f*cos(w*t), or give drive.txt)")
        self.w, self.model = w, model
        l1, l2 = model.lam
        self.lams = np.array([l1, np.conj(l1), l2, np.conj(l2)])
        s1, s2 = (lin.shape for lin in model.linear)
        self.phis = np.array([s1, np.conj(s1), s2, np.conj(s2)])
        v1, v2 = (lin.left for lin in model.linear)
        self.lefts = np.array([v1, np.conj(v1), v2, np.conj(v2)])
        nu = np.array([1, -1, model.ratio, -model.ratio])
        self.kept = kept = np.flatnonzero(nu == kappa)
        M, C, K = w.mass, _damping(w), w.stiffness
        if w.size <= DENSE_SOLVES:  # products with small sparse matrices cost more
            M, C, K = M.toarray(), C.toarray(), K.toarray()
        self.M, self.C, self.K = M, C, K
        # NOTE: the borders are affine in s: b_j = s·Mφ_j + (Λ_j M + C)φ_j and
        # c_i = s·Mᵀw_i + (Cᵀ + Λ_i Mᵀ)w_i, made once
        MPhi = np.array([M @ self.phis[j] for j in kept]).T
        self.b = (MPhi, np.array([(self.lams[j] * M + C) @ self.phis[j] for j in kept]).T)
        self.c = (np.array([M.T @ self.lefts[i] for i in kept]),
                  np.array([(C.T + self.lams[i] * M.T) @ self.lefts[i] for i in kept]))
        self.d = self.lefts[kept] @ MPhi
        self.force = w.drive.astype(complex) / 2
        self.cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self.chebyshev: tuple | None = None

    def interpolate(self, lo: float, hi: float) -> None:
        """``a(Ω)`` over ``[lo, hi]`` as a Chebyshev series (nodes doubled from
        :data:`CHEBYSHEV_NODES` until the midpoints agree to :data:`INTERPOLATED`): the
        continuation asks ``a`` and ``da/dΩ`` thousands of times."""
        mid, half = (hi + lo) / 2, (hi - lo) / 2
        N = CHEBYSHEV_NODES
        while True:
            nodes = np.cos(np.pi * (np.arange(N) + 0.5) / N)
            values = np.array([self.at(mid + half * x)[0] for x in nodes])
            coef = chebyshev.chebfit(nodes, values, N - 1)
            probes = np.cos(np.pi * np.arange(1, N) / N)
            exact = np.array([self.at(mid + half * x)[0] for x in probes])
            error = np.max(np.abs(chebyshev.chebval(probes, coef).T - exact))
            if error <= INTERPOLATED * max(np.max(np.abs(values)), 1e-300) or N >= CHEBYSHEV_MOST:
                break
            N *= 2
        self.chebyshev = (mid, half, [complex(c) for c in coef[:, 0]],
                          [complex(c) for c in coef[:, 1]],
                          [complex(c) for c in chebyshev.chebder(coef[:, 0]) / half],
                          [complex(c) for c in chebyshev.chebder(coef[:, 1]) / half])

    def forcing(self, omega: float) -> np.ndarray:
        """``a(Ω)`` (interpolated where :meth:`interpolate` was called)."""
        if self.chebyshev is None:
            return self.at(omega)[0]
        mid, half, a1, a2, _, _ = self.chebyshev
        x = (omega - mid) / half
        return np.array([_clenshaw(a1, x), _clenshaw(a2, x)])

    def slope(self, omega: float) -> np.ndarray:
        """``da/dΩ``: the Chebyshev series' derivative, or a central difference."""
        if self.chebyshev is None:
            h = DIFFERENCE * max(1.0, abs(omega))
            return (self.at(omega + h)[0] - self.at(omega - h)[0]) / (2 * h)
        mid, half, _, _, d1, d2 = self.chebyshev
        x = (omega - mid) / half
        return np.array([_clenshaw(d1, x), _clenshaw(d2, x)])

    def at(self, omega: float) -> tuple[np.ndarray, np.ndarray]:
        if omega not in self.cache:
            s = 1j * omega
            L = s * s * self.M + s * self.C + self.K
            if sparse.issparse(L):
                L = sparse.csc_array(L)
            lams = self.lams[self.kept]
            X, sigma = _bordered(L, s * self.b[0] + self.b[1], s * self.c[0] + self.c[1],
                                 self.d, self.force, np.zeros(len(self.kept)),
                                 bool(np.any(np.abs(s - lams) <= BORDERED * np.abs(lams))),
                                 (0, (0, 0, 0, 0), "drive"))
            a = np.zeros(2, dtype=complex)
            for j, value in zip(self.kept, np.atleast_1d(sigma), strict=True):
                a[j // 2] = value
            self.cache[omega] = (a, X)
        return self.cache[omega]


def _clenshaw(c: list[complex], x: float) -> complex:
    """``Σ c_j T_j(x)`` by Clenshaw's recurrence, in Python scalars (NumPy's ``chebval``
    costs ~80 µs a call on two coefficients; the continuation makes thousands)."""
    b1 = b2 = 0j
    for cj in reversed(c[1:]):
        b1, b2 = 2 * x * b1 - b2 + cj, b1
    return x * b1 - b2 + c[0]


class _Balance:
    """``u' = 0`` in ``x = (Re u₁, Im u₁, Re u₂, Im u₂)`` and Ω: ``residual``, ``jacobian``
    and ``d_omega``, as :func:`analysis.continuation._continue` asks of a balance."""

    def __init__(self, model: ResonantSSM, drive: _Drive, kappa: int) -> None:
        self.lams = np.array(model.lam)
        self.nu = np.array([1, model.ratio]) / kappa
        terms = model.terms()
        self.E = [np.array([t.monomial for t in terms if t.mode == k], dtype=int).reshape(-1, 4)
                  for k in (1, 2)]
        self.c = [np.array([t.coefficient for t in terms if t.mode == k], dtype=complex)
                  for k in (1, 2)]
        self.drive = drive
        self.lowered = [np.maximum(E[:, None, :] - np.eye(4, dtype=int)[None], 0)
                        for E in self.E]
        self.weighted = [c[:, None] * E for c, E in zip(self.c, self.E, strict=True)]

    @staticmethod
    def _u(x: np.ndarray) -> np.ndarray:
        u1, u2 = x[0] + 1j * x[1], x[2] + 1j * x[3]
        return np.array([u1, np.conj(u1), u2, np.conj(u2)])

    def complex_residual(self, x: np.ndarray, omega: float) -> np.ndarray:
        U = self._u(x)
        a = self.drive.forcing(omega)
        out = (self.lams - 1j * self.nu * omega) * U[[0, 2]] + a
        for k in range(2):
            if len(self.c[k]):
                out[k] += self.c[k] @ np.prod(U[None, :] ** self.E[k], axis=1)
        return out

    def residual(self, x: np.ndarray, omega: float) -> np.ndarray:
        G = self.complex_residual(x, omega)
        return np.array([G[0].real, G[0].imag, G[1].real, G[1].imag])

    def jacobian(self, x: np.ndarray, omega: float) -> np.ndarray:
        U = self._u(x)
        dU = np.zeros((2, 4), dtype=complex)  # ∂G_k/∂(u₁, ū₁, u₂, ū₂)
        for k in range(2):
            dU[k, 2 * k] = self.lams[k] - 1j * self.nu[k] * omega
            if len(self.E[k]):  # ∂(u^m)/∂U_j = m_j u^(m − e_j), every j at once
                dU[k] += np.sum(self.weighted[k] * np.prod(U ** self.lowered[k], axis=2), axis=0)
        re = dU[:, 0::2] + dU[:, 1::2]  # ∂/∂Re u_j
        im = 1j * (dU[:, 0::2] - dU[:, 1::2])  # ∂/∂Im u_j
        J = np.empty((4, 4))
        J[0::2, 0::2], J[1::2, 0::2] = re.real, re.imag
        J[0::2, 1::2], J[1::2, 1::2] = im.real, im.imag
        return J

    def d_omega(self, x: np.ndarray, omega: float) -> np.ndarray:
        da = self.drive.slope(omega)
        U = self._u(x)
        G = -1j * self.nu * U[[0, 2]] + da
        return np.array([G[0].real, G[0].imag, G[1].real, G[1].imag])


def pair_response(model: ResonantSSM, span: tuple[float, float], outputs: np.ndarray
                  ) -> PairResponse:
    """The forced response of ``model``'s system over Ω in ``span``: every steady state on
    the curves from the linear response at both ends, its stability and amplitudes."""
    lo, hi = span
    l1, l2 = model.lam
    middle = (lo + hi) / 2
    kappa = 1 if abs(middle - l1.imag) <= abs(middle - l2.imag) else model.ratio
    drive = _Drive(model, kappa)
    drive.interpolate(lo, hi)
    balance = _Balance(model, drive, kappa)

    def linear(omega: float) -> np.ndarray:
        a = drive.forcing(omega)
        u = -a / (balance.lams - 1j * balance.nu * omega)
        return np.array([u[0].real, u[0].imag, u[1].real, u[1].imag])

    def ends():
        return [(lo, linear(lo), 1.0), (hi, linear(hi), -1.0)], True

    from .continuation import _continue  # NOTE: here: its imports cost 0.5 s, and an
    # undriven pair needs none of it

    step = (hi - lo) / STEPS
    where = f"modes {model.modes[0]},{model.modes[1]}"

    def trace(starts) -> Continuation:
        return _continue(balance, starts, lo, hi, step, STEPS, STEPS * POINT_SECONDS,
                         POINT_SECONDS, MAX_POINTS, where)

    curves = [trace(ends)]
    for y in _branch_seeds(balance, curves[0], step):
        if all(np.min(np.linalg.norm(np.column_stack([c.x, c.omega]) - y, axis=1)) > step
               for c in curves):
            curves.append(trace(lambda y=y: ([(y[-1], y[:-1], 1.0), (y[-1], y[:-1], -1.0)],
                                             True)))
    pieces, chosen_omega, chosen_x, beyond = [], [], [], 0
    for curve in curves:
        keep = (curve.omega >= lo) & (curve.omega <= hi)
        outside = np.maximum(np.hypot(curve.x[:, 0], curve.x[:, 1]),
                             np.hypot(curve.x[:, 2], curve.x[:, 3])) > model.radius
        beyond += int(np.sum(keep & outside))
        keep &= ~outside
        if kappa > 1:  # NOTE: one of the κ copies of a subharmonic state, |arg u₁| ≤ π/κ
            # (a drive period later its motion is the same with u₁ turned by 2π/κ)
            angle = np.angle(curve.x[:, 0] + 1j * curve.x[:, 1])
            small = np.hypot(curve.x[:, 0], curve.x[:, 1]) <= SAME * np.max(np.abs(curve.x))
            keep &= small | ((-np.pi / kappa < angle) & (angle <= np.pi / kappa))
        starts = set(curve.pieces)
        for i in range(len(curve.omega)):
            if keep[i] and (i in starts or not keep[i - 1]):
                pieces.append(len(chosen_omega))
            if keep[i]:
                chosen_omega.append(curve.omega[i])
                chosen_x.append(curve.x[i])
    omegas, xs = np.array(chosen_omega), np.array(chosen_x)
    us = xs[:, 0::2] + 1j * xs[:, 1::2]
    amplitude = peak_amplitude(_harmonics(model, drive, kappa, omegas, us, outputs))
    rates = [float(np.max(np.linalg.eigvals(balance.jacobian(x, omega)).real))
             for omega, x in zip(omegas, xs, strict=True)]
    states = tuple(
        PairState(float(omega), (complex(u[0]), complex(u[1])), (abs(u[0]), abs(u[1])), amp,
                  rate < 0, _start(model, drive, float(omega), u), rate)
        for omega, u, amp, rate in zip(omegas, us, amplitude, rates, strict=True))
    folds = sorted(f for c in curves for f in c.folds if lo <= f <= hi
                   and _inside(balance, c, f, model.radius))
    folds = [f for i, f in enumerate(folds) if i == 0 or f - folds[i - 1] > SAME * abs(f)]
    return PairResponse(kappa, states, tuple(sorted({p for p in pieces if p < len(states)})),
                        tuple(folds), tuple(drive.at(middle)[0]), beyond)


def _inside(balance: _Balance, curve: Continuation, fold: float, radius: float) -> bool:
    """Whether the traced point nearest the fold ``fold`` (in Ω, where ``dΩ`` turns) lies
    inside the radius."""
    turns = np.flatnonzero(np.diff(np.sign(np.diff(curve.omega))) != 0) + 1
    if not len(turns):
        return True
    i = turns[np.argmin(np.abs(curve.omega[turns] - fold))]
    x = curve.x[i]
    return max(math.hypot(x[0], x[1]), math.hypot(x[2], x[3])) <= radius


def _branch_seeds(balance: _Balance, curve: Continuation, step: float) -> list[np.ndarray]:
    """A point on each branch crossing the traced curve (``y = (x, Ω)``): where ``det ∂R/∂x``
    changes sign between neighbours with no fold between them (a branch point: the
    extended Jacobian's null space is two-dimensional there), located on the chord and
    corrected onto the curve, then a step along the null direction orthogonal to the curve,
    each way, corrected (:func:`analysis.continuation._corrector`) — kept where it lands off
    the curve."""
    from .continuation import _corrector, _extended_jacobian

    ys = np.column_stack([curve.x, curve.omega])
    dets = [np.linalg.det(balance.jacobian(y[:-1], y[-1])) for y in ys]
    breaks = set(curve.pieces)
    seeds = []
    for i in range(len(ys) - 1):
        if i + 1 in breaks or (dets[i] > 0) == (dets[i + 1] > 0):
            continue
        a, b = ys[i], ys[i + 1]
        if any(min(a[-1], b[-1]) <= f <= max(a[-1], b[-1]) for f in curve.folds):
            continue
        chord = (b - a) / np.linalg.norm(b - a)
        try:
            bp = _corrector(balance, a + dets[i] / (dets[i] - dets[i + 1]) * (b - a), chord)
            _, _, vt = np.linalg.svd(_extended_jacobian(balance, bp))
            null = vt[-2:]
            other = null.T @ np.linalg.lstsq(null.T, chord, rcond=None)[0]
            direction = chord - other if np.linalg.norm(chord - other) > 0.5 else null[0]
            direction = null.T @ (null @ direction)
            direction /= np.linalg.norm(direction)
            for sign in (1.0, -1.0):
                y = _corrector(balance, bp + sign * 2 * step * direction, direction)
                if np.all(np.isfinite(y)) and np.linalg.norm(y - bp) > step and np.max(
                        np.abs(balance.residual(y[:-1], y[-1]))) < 1e-9:
                    seeds.append(y)
        except np.linalg.LinAlgError:
            continue
    return seeds


def _harmonics(model: ResonantSSM, drive: _Drive, kappa: int, omegas: np.ndarray,
               us: np.ndarray, outputs: np.ndarray) -> np.ndarray:
    """The outputs' Fourier coefficients in ``φ = Ωt/κ`` of steady states (``us``:
    ``(P, 2)``; ``(P, 2H + 1, outputs)``, harmonic ``h`` at index ``h + H``, ``H = rK``)."""
    r, K = model.ratio, model.order
    H = max(r * K, kappa)
    nu = np.array([1, -1, r, -r])
    U = np.stack([us[:, 0], np.conj(us[:, 0]), us[:, 1], np.conj(us[:, 1])], axis=1)
    out = np.zeros((len(us), 2 * H + 1, len(outputs)), dtype=complex)
    for k in range(1, K + 1):
        E = model.basis.exponents[k]
        powers = np.prod(U[:, None, :] ** E[None], axis=2)  # (P, N_k)
        spread = np.zeros((2 * H + 1, len(E)))
        spread[E @ nu + H, np.arange(len(E))] = 1.0
        out += np.einsum("hm,pm,mo->pho", spread, powers, model.W[k][:, outputs])
    X = np.array([drive.at(float(omega))[1][outputs] for omega in omegas])
    out[:, H + kappa] += X
    out[:, H - kappa] += np.conj(X)
    return out


def _start(model: ResonantSSM, drive: _Drive, omega: float, u: np.ndarray) -> np.ndarray:
    """``(x(0), x'(0))`` of a steady state."""
    x, v = model.state(complex(u[0]), complex(u[1]))
    X = drive.at(omega)[1]
    return np.concatenate([x + 2 * X.real, v + 2 * (1j * omega * X).real])


@dataclass(frozen=True)
class Family:
    """A family of motions of the SSM the command reports: one mode alone on its invariant
    plane (``mode``, ``gamma``: its normal form ``p_k' = p_k Σ_j γ_j (p_k p̄_k)^j``), at
    ``rho`` (that mode's ``ρ_k``), with ``omega``, ``damping_ratio`` and each output's
    ``amplitude`` (max |x_i| over a period)."""

    mode: int
    gamma: tuple[complex, ...]
    rho: np.ndarray = field(repr=False)
    omega: np.ndarray = field(repr=False)
    damping_ratio: np.ndarray = field(repr=False)
    amplitude: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class ResonantReduction:
    """What ``ssm SYSTEM --mode M1,M2`` reports: the 4-D SSM, the outputs, the kept terms of
    the reduced dynamics, the single-mode families where their planes are invariant, the
    forced response (driven) and the coupled modes (undamped)."""

    text: str
    model: ResonantSSM
    outputs: np.ndarray
    names: tuple[str, ...]
    terms: tuple[Term, ...]
    families: tuple[Family, ...]
    response: PairResponse | None
    span: tuple[float, float] | None
    coupled: tuple[CoupledMode, ...] = ()
    slow_flow: tuple[float, float] | None = None  # c_k of slowflow's variables, where it applies


def reduce_pair(system: System, modes: tuple[int, ...], order: int,
                outputs: list[int] | None = None, rho_max: float | None = None,
                span: tuple[float, float] | None = None) -> ResonantReduction:
    """The 4-D SSM of ``modes`` to ``order``, its terms and families up to ``rho_max``
    (default :data:`analysis.ssm_forced.REACH` of the radius) and, driven, its forced
    response over ``span`` (default :data:`analysis.ssm_forced.DEFAULT_SPAN` about the lower
    mode's ``|λ|``)."""
    model = resonant_ssm(system, modes, order)
    if outputs is None:
        outputs = (list(range(system.size)) if system.size <= NAMED_OUTPUTS else sorted(
            {leading(lin.shape) for lin in model.linear}))
    outputs = np.array(outputs, dtype=np.int64)
    names = tuple(str(system.coordinates[i]) for i in outputs)
    end = rho_max
    if end is None:
        end = REACH * model.radius if math.isfinite(model.radius) else 1.0
    elif end > model.radius:
        raise InputError(f"--rho-max {rho_max:g}: beyond the SSM's estimated radius "
                         f"{model.radius:.6g} in max |p_k| ({model.radius_how})")
    rho = np.linspace(0.0, end, BACKBONE_POINTS)
    families = []
    for mode in (1, 2):
        gamma = model.backbone(mode)
        if gamma is None:
            continue
        g = sum(c * rho ** (2 * j) for j, c in enumerate(gamma))
        families.append(Family(model.modes[mode - 1], gamma, rho, g.imag,
                               -g.real / np.abs(g) + 0.0,
                               peak_amplitude(_plane_harmonics(model, mode, rho, outputs))))
    response = None
    if system.matrices.drive is not None:
        lam = abs(model.lam[0])
        span = (float(span[0]), float(span[1])) if span is not None else (
            (1 - DEFAULT_SPAN) * lam, (1 + DEFAULT_SPAN) * lam)
        response = pair_response(model, span, outputs)
    elif span is not None:
        raise InputError("--omega: the system is not driven (drive one equation with "
                         "f*cos(w*t), or give drive.txt)")
    amplitudes = np.linspace(end / (BACKBONE_POINTS - 1), end, BACKBONE_POINTS - 1)
    return ResonantReduction(system.text, model, outputs, names, tuple(model.terms()),
                             tuple(families), response, span,
                             coupled_modes(model, amplitudes, outputs),
                             _slow_flow_variables(system, model))


def _slow_flow_variables(system: System, model: ResonantSSM) -> tuple[float, float] | None:
    """``c_k`` of ``slowflow SYSTEM``'s amplitudes (``a_k = |c_k| ρ_k``,
    :func:`analysis.ssm_resonant.slow_flow_scale`) where its flow applies: a system written
    as text, undamped, no velocity in the force, the two ω₀² rational in the exact ratio
    ``r²`` (its shapes: :func:`derive.resonance._shapes`); ``None`` elsewhere."""
    from ..derive.resonance import _shapes
    from .ssm_resonant import slow_flow_scale

    if not system.exact or system.damping is not None or any(
            f.has(*system.velocities) for f in system.force):
        return None
    try:
        lams = system.modes()
    except InputError:  # too many coordinates for exact modes
        return None
    pair = [lams[m - 1] for m in model.modes]
    if not all(lam.is_Rational for lam in pair) or pair[1] != model.ratio**2 * pair[0]:
        return None
    return slow_flow_scale(model, [_shapes(system, lam)[0] for lam in pair])


def _plane_harmonics(model: ResonantSSM, mode: int, rho: np.ndarray, outputs: np.ndarray
                     ) -> np.ndarray:
    """The outputs' Fourier coefficients in ``θ_k`` on mode ``mode``'s plane at each ρ_k
    (``(P, 2K + 1, outputs)``, harmonic ``h`` at index ``h + K``)."""
    K = model.order
    first = 0 if mode == 1 else 2
    out = np.zeros((len(rho), 2 * K + 1, len(outputs)), dtype=complex)
    for k in range(1, K + 1):
        for r in range(k + 1):
            e = [0, 0, 0, 0]
            e[first], e[first + 1] = k - r, r
            row = model.basis.index[k][tuple(e)]
            out[:, k - 2 * r + K] += rho[:, None] ** k * model.W[k][row, outputs][None, :]
    return out


@dataclass(frozen=True)
class CoupledMode:
    """Phase-locked periodic motions of an undamped pair at one phase difference ``psi``
    (0 or π): ``ρ₁, ρ₂`` constant, ``ψ' = θ₂' − rθ₁' = 0``; at each point ``rho`` (``(P,
    2)``), ``omega`` (``θ₁'``: the motion has period ``2π/ω``, mode 2 turning r times as
    fast) and each output's ``amplitude``."""

    psi: float
    rho: np.ndarray = field(repr=False)
    omega: np.ndarray = field(repr=False)
    amplitude: np.ndarray = field(repr=False)


CONSERVATIVE = 1e-10
# NOTE: the kept coefficients' real parts below this fraction of |λ| (and no linear damping):
# the pair is conservative, ρ_k' vanishes at ψ = 0 and π, and the coupled modes are families
# of periodic orbits; a damped pair's amplitudes decay and it has none.
ANGLES = 64
# NOTE: samples of the ray's angle β (ρ₁ = s cos β, ρ₂ = s sin β) in (0, π/2) where ψ' changes
# sign: each bracket refined by false position to rounding.


def coupled_modes(model: ResonantSSM, amplitudes: np.ndarray, outputs: np.ndarray,
                  top: int | None = None) -> tuple[CoupledMode, ...]:
    """The coupled modes of an undamped pair at each ``s = √(ρ₁² + ρ₂²)`` of ``amplitudes``
    (the reduced dynamics to order ``top``, default all): every root ``β`` of ``ψ'`` in
    ``(0, π/2)`` at ``ψ = 0`` and ``ψ = π``; none for a damped pair."""
    damping = model.matrices.damping
    scale = max(abs(lam) for lam in model.lam)
    if (damping is not None and damping.count_nonzero()) or any(
            abs(t.coefficient.real) > CONSERVATIVE * scale for t in model.terms(top)):
        return ()
    terms = model.terms(top)
    beta = np.pi / 2 * (np.arange(ANGLES) + 0.5) / ANGLES
    out = []
    for psi in (0.0, np.pi):
        points = []
        for s in amplitudes:
            def locked(b, s: float = s, psi: float = psi):
                return _locked_rates(model, terms, s * np.cos(b), s * np.sin(b), psi)[0]

            values = locked(beta)
            for a, b, fa, fb in zip(beta[:-1], beta[1:], values[:-1], values[1:], strict=True):
                if fa == 0 or (fa > 0) != (fb > 0):
                    run = secant(lambda x: float(locked(x)), a, b, fa, fb, tol=1e-15,
                                 bracketed=True)
                    root = float(run.x)
                    rho = (s * math.cos(root), s * math.sin(root))
                    points.append((rho, float(_locked_rates(model, terms, *rho, psi)[1])))
        if points:
            rho = np.array([p[0] for p in points])
            omega = np.array([p[1] for p in points])
            out.append(CoupledMode(psi, rho, omega, peak_amplitude(
                _locked_harmonics(model, rho, psi, outputs))))
    return tuple(out)


def _locked_rates(model: ResonantSSM, terms: list[Term], rho1, rho2, psi: float):
    """``(ψ', θ₁')`` at ``ρ₁, ρ₂`` (arrays) and ``ψ``, from the polar form of the kept terms:
    ``θ_k' = Im λ_k + Σ Im(c e^{iqψ}) ρ₁^{a}ρ₂^{b} / ρ_k``."""
    rho1, rho2 = np.asarray(rho1, dtype=float), np.asarray(rho2, dtype=float)
    theta = [np.full(rho1.shape, lam.imag) for lam in model.lam]
    for t in terms:
        value = (t.coefficient * np.exp(1j * t.psi * psi)).imag * rho1**t.rho1 * rho2**t.rho2
        theta[t.mode - 1] = theta[t.mode - 1] + value / (rho1 if t.mode == 1 else rho2)
    return theta[1] - model.ratio * theta[0], theta[0]


def _locked_harmonics(model: ResonantSSM, rho: np.ndarray, psi: float, outputs: np.ndarray
                      ) -> np.ndarray:
    """The outputs' Fourier coefficients in ``θ = θ₁`` of coupled motions (``p₁ = ρ₁e^{iθ}``,
    ``p₂ = ρ₂e^{i(rθ + ψ)}``; ``(P, 2H + 1, outputs)``, ``H = rK``)."""
    r, K = model.ratio, model.order
    H = r * K
    phase = np.exp(1j * psi)
    us = np.stack([rho[:, 0] + 0j, rho[:, 1] * phase], axis=1)
    nu = np.array([1, -1, r, -r])
    U = np.stack([us[:, 0], np.conj(us[:, 0]), us[:, 1], np.conj(us[:, 1])], axis=1)
    out = np.zeros((len(us), 2 * H + 1, len(outputs)), dtype=complex)
    for k in range(1, K + 1):
        E = model.basis.exponents[k]
        powers = np.prod(U[:, None, :] ** E[None], axis=2)
        spread = np.zeros((2 * H + 1, len(E)))
        spread[E @ nu + H, np.arange(len(E))] = 1.0
        out += np.einsum("hm,pm,mo->pho", spread, powers, model.W[k][:, outputs])
    return out
