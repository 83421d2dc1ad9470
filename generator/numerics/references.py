"""Closed-form and high-precision references: the Duffing period and cn, the pendulum's
period, a limit cycle by DOP853 to 1e-13, Mathieu's characteristic values by the
truncated Hill matrix, Newton and mpmath."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ellipj, ellipk

from ..limits import EXCHANGE_MAX_STEPS
from .newton import newton, secant


def duffing_period_exact(A: ArrayLike, eps: ArrayLike) -> np.ndarray:
    """``T = 4K(m)/√(1+x)``, ``m = x/(2(1+x))``, ``x = εA²`` (notes App. 4.9); NaN for x ≤ -1.

    SciPy's ``ellipk`` takes any ``m < 1``, so softening springs (``-1 < x < 0``, ``m < 0``)
    are exact too.
    """
    x = np.asarray(eps, dtype=float) * np.asarray(A, dtype=float) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        out = 4 * ellipk(x / (2 * (1 + x))) / np.sqrt(1 + x)
    return np.where(x > -1, out, np.nan)


def duffing_q_exact(t: ArrayLike, A: ArrayLike, eps: ArrayLike) -> np.ndarray:
    """``q(t) = A cn(√(1+x) t | m)`` for ``x = εA² ≥ 0`` (SciPy's ``ellipj`` needs 0 ≤ m ≤ 1)."""
    A = np.asarray(A, dtype=float)
    x = np.asarray(eps, dtype=float) * A**2
    if np.any(x < 0):
        raise ValueError("duffing_q_exact: x = εA² < 0 needs cn with m < 0 (use mpmath)")
    m = x / (2 * (1 + x))
    return A * ellipj(np.sqrt(1 + x) * np.asarray(t, dtype=float), m)[1]


def pendulum_period_exact(theta0: ArrayLike) -> np.ndarray:
    """``T = 4K(sin²(θ₀/2))`` (notes App. 4.1); NaN for ``|θ₀| ≥ π``."""
    th = np.asarray(theta0, dtype=float)
    out = 4 * ellipk(np.sin(th / 2) ** 2)
    return np.where(np.abs(th) < np.pi, out, np.nan)


@dataclass(frozen=True)
class CycleReference:
    """A limit cycle shot by SciPy's DOP853: ``q(0)`` at the maximum (``q̇(0) = 0``), the
    period, and ``accuracy``: the relative difference of the periods at ``rtol`` and at
    ``100 rtol`` (the reference's own error is below it)."""

    q0: float
    period: float
    accuracy: float


CYCLE_RTOL = 1e-13
# NOTE: DOP853's tolerance for the references: at 1e-13 (atol 1e-14) van der Pol's period
# agrees with the 1e-11 run to ≤ 1e-12 up to ε = 10 (6.663286859323127 at ε = 1: 5e-16 from
# the literature's 6.66328685932313019)


def _cycle_return(rhs: Callable, a: float, rtol: float, t_max: float) -> tuple[float, float]:
    """From the maximum ``(a, 0)`` to the next maximum: ``(q, t)`` there."""
    from scipy.integrate import solve_ivp

    def turn(t: float, y: np.ndarray) -> float:
        return y[1]
    turn.direction = -1  # q̇ from + to −: a maximum of q
    sol = solve_ivp(rhs, (0.0, t_max), [a, 0.0], method="DOP853", rtol=rtol, atol=rtol / 10,
                    events=turn)
    for t, y in zip(sol.t_events[0], sol.y_events[0], strict=True):
        if t > 1e-9:
            return float(y[0]), float(t)
    return math.nan, math.nan


def _cycle_rhs(model: object, eps: float) -> Callable:
    """The right-hand side ``(q̇, q̈)`` of ``q̈ + q = ε f(q, q̇)``, ``f = Σ c q^a q̇^b`` (the
    terms of a :class:`models.SelfExcited`), for SciPy's ``solve_ivp``."""
    terms = [(a, b, float(c)) for a, b, c in model.terms]

    def rhs(t: float, y: np.ndarray) -> list[float]:
        q, v = y.tolist()  # Python floats: a third faster than NumPy's scalars, the same digits
        force = 0.0
        for a, b, c in terms:
            force += c * q**a * v**b
        return [v, -q + eps * force]
    return rhs


def cycle_reference(model: object, eps: float, guess: float = 2.0, period: float = 2 * np.pi,
                    rtol: float = CYCLE_RTOL) -> CycleReference:
    """The attracting limit cycle of ``q̈ + q = ε f(q, q̇)`` (a :class:`models.SelfExcited`)
    at any ``eps > 0``, relaxation oscillations included: the return map to the maximum of q
    (Poincaré section q̇ = 0), a few plain returns from ``guess`` and then the secant method
    on ``P(a) − a`` (:func:`numerics.newton.secant`); repeated at ``100 rtol`` for
    :attr:`CycleReference.accuracy`."""
    rhs = _cycle_rhs(model, eps)

    def solve(tol: float) -> tuple[float, float]:
        t_max = 4 * max(period, 2 * np.pi + 2 * eps)
        a = guess
        for _ in range(3):
            a, _ = _cycle_return(rhs, a, tol, t_max)
        def gap(a: float) -> float:
            return _cycle_return(rhs, a, tol, t_max)[0] - a

        a0, a1 = a, a * (1 + 1e-7)
        run = secant(gap, a0, a1, gap(a0), gap(a1), tol=1e-15, max_iter=30)
        return _cycle_return(rhs, run.x, tol, t_max)

    q0, T = solve(rtol)
    _, T_coarse = solve(rtol * 100)
    return CycleReference(q0, T, abs(T - T_coarse) / T)


def cycle_samples(model: object, eps: float, reference: CycleReference, points: int
                  ) -> tuple[np.ndarray, np.ndarray]:
    """``(t, q(t))`` at ``points`` equally spaced times of one period of the shot cycle
    (:func:`cycle_reference`), from its maximum ``(q(0), 0)`` by DOP853 at its tolerance."""
    from scipy.integrate import solve_ivp

    t = reference.period * np.arange(points) / points
    sol = solve_ivp(_cycle_rhs(model, eps), (0.0, reference.period), [reference.q0, 0.0],
                    method="DOP853", rtol=CYCLE_RTOL, atol=CYCLE_RTOL / 10, t_eval=t)
    return t, sol.y[0]


def mathieu_reference(kind: str, m: int, q: float, size: int | None = None,
                      dps: int | None = None) -> float:
    """Mathieu's characteristic value ``a_m(q)`` or ``b_m(q)`` (DLMF §28.2, ``y'' + (a − 2q
    cos 2z) y = 0``) as an eigenvalue of the truncated recurrence of the Fourier coefficients
    (DLMF 28.4.5–8), symmetrised (``√2`` in the ``ce_(2n)`` coupling): ``size`` terms (enough
    that the tail decays, ~|q|^(1/2) + 30 by default), in float64 or, with ``dps``, in mpmath
    at that precision.  The eigenvalues of each parity class are sorted, the m-th taken."""
    even = m % 2 == 0
    n = size if size is not None else int(2 * math.sqrt(abs(q)) + 40)
    if kind == "a":
        orders = [2 * k + (0 if even else 1) for k in range(n)]
    else:
        orders = [2 * k + (2 if even else 1) for k in range(n)]
    diag = [float(r * r) for r in orders]
    off = [q] * (n - 1)
    if kind == "a" and even:
        off[0] = q * math.sqrt(2)  # ce_(2n): A_0 couples to A_2 through 2q (DLMF 28.4.5)
    if kind == "a" and not even:
        diag[0] = 1.0 + q  # ce_(2n+1): a − 1 − q on A_1 (DLMF 28.4.6)
    if kind == "b" and not even:
        diag[0] = 1.0 - q  # se_(2n+1): a − 1 + q on B_1 (DLMF 28.4.7)
    index = m // 2 if kind == "a" or not even else m // 2 - 1
    if dps is None:
        from scipy.linalg import eigvalsh_tridiagonal

        return float(eigvalsh_tridiagonal(np.array(diag), np.array(off))[index])
    import mpmath

    with mpmath.workdps(dps):
        qq = mpmath.mpf(q)
        A = mpmath.zeros(n, n)
        for i in range(n):
            A[i, i] = mpmath.mpf(orders[i] ** 2)
        if kind == "a" and not even:
            A[0, 0] = 1 + qq
        if kind == "b" and not even:
            A[0, 0] = 1 - qq
        for i in range(n - 1):
            A[i, i + 1] = A[i + 1, i] = qq * (mpmath.sqrt(2) if (kind == "a" and even
                                                                 and i == 0) else 1)
        values = sorted(mpmath.eigsy(A, eigvals_only=True))
        return float(values[index])


def mathieu_recurrence(kind: str, m: int, rows: int
                       ) -> tuple[int, tuple[tuple[int, int], ...], tuple[int, ...]]:
    """The symmetrised recurrence of the Fourier coefficients of ``ce_m`` or ``se_m`` (DLMF
    28.4.5–8) as exact integers, ``rows`` of it: the diagonal ``c_j = r_j² + s_j q`` as
    ``(r_j², s_j)``, the squared couplings ``e_j² = t_j q²`` as ``t_j`` (2 for ``A_0``–``A_2``,
    the ``√2`` of the symmetrised ``ce_(2n)``), and the index of ``m`` among its class's sorted
    eigenvalues."""
    even = m % 2 == 0
    if kind == "a":
        orders = [2 * k + (0 if even else 1) for k in range(rows)]
    else:
        orders = [2 * k + (2 if even else 1) for k in range(rows)]
    diag = [(r * r, 0) for r in orders]
    if not even:
        diag[0] = (1, 1 if kind == "a" else -1)  # a − 1 ∓ q on A_1, B_1 (DLMF 28.4.6–7)
    couplings = [2 if (kind == "a" and even and j == 0) else 1 for j in range(rows - 1)]
    index = m // 2 if kind == "a" or not even else m // 2 - 1
    return index, tuple(diag), tuple(couplings)


def mathieu_newton(kind: str, m: int, q: ArrayLike, start: ArrayLike, rows: int,
                   steps: int) -> np.ndarray:
    """Newton steps on ``det(T_rows − a)`` of :func:`mathieu_recurrence`'s matrix from
    ``start``, vectorised over q (DLMF 28.6.16–20 in determinant form, no division but the
    step's).  The matrix is split after row ``k = rows // 2``: the leading minors ``p_j =
    (c_j − a) p_(j−1) − e²_(j−1) p_(j−2)`` (rows 0…k) and the trailing ones ``s_j = (c_j − a)
    s_(j+1) − e²_j s_(j+2)`` (rows j…rows−1) are two independent chains, and ``det = p_k
    s_(k+1) − e²_k p_(k−1) s_(k+2)``; the a-derivatives run beside them.  The emitted
    evaluators unroll the same steps (:func:`lower.mathieu_newton_steps`)."""
    _, diag, couplings = mathieu_recurrence(kind, m, rows)
    q = np.asarray(q, dtype=float)
    a = np.asarray(start, dtype=float) + 0.0 * q
    qq = q * q
    k = rows // 2
    # NOTE: Newton's steps by hand, not numerics.newton: exactly ``steps`` of them, no stopping
    # test and no guard, in the order the emitted evaluators unroll them, whose values the
    # verification compares with these.
    for _ in range(steps):
        one, zero = np.ones_like(a), np.zeros_like(a)
        p_prev, dp_prev, p, dp = one, zero, diag[0][0] + diag[0][1] * q - a, -one
        for j in range(1, k + 1):
            c = diag[j][0] + diag[j][1] * q - a
            e2 = couplings[j - 1] * qq
            p, p_prev, dp, dp_prev = (c * p - e2 * p_prev, p, c * dp - p - e2 * dp_prev, dp)
        s_next, ds_next, s, ds = one, zero, diag[rows - 1][0] + diag[rows - 1][1] * q - a, -one
        for j in range(rows - 2, k, -1):
            c = diag[j][0] + diag[j][1] * q - a
            e2 = couplings[j] * qq
            s, s_next, ds, ds_next = (c * s - e2 * s_next, s, c * ds - s - e2 * ds_next, ds)
        e2 = couplings[k] * qq
        det = p * s - e2 * p_prev * s_next
        ddet = dp * s + p * ds - e2 * (dp_prev * s_next + p_prev * ds_next)
        a = a - det / ddet
    return a


def mathieu_truncation_bound(kind: str, m: int, q: float, a: float, rows: int) -> float:
    """A bound on ``|a_rows − a|``: the eigenvalue of the ``rows``-row truncation (N = rows)
    against the exact ``a`` of the infinite recurrence, with ``v`` its unit eigenvector.

    Cutting the coupling ``e = e_(N−1)`` leaves ``A' = T_N ⊕ T_tail`` and ``(A' − a)v =
    −e(v_N u_(N−1) + v_(N−1) u_N)``: the Rayleigh quotient ``ρ = a − 2e v_(N−1) v_N`` and the
    residual ``r ≤ e (v²_(N−1) + v²_N)^½``; by Kato–Temple ``|μ − ρ| ≤ r²/g`` for the one
    eigenvalue ``μ`` of ``A'`` within the gap ``g`` of ``ρ`` to the rest of its spectrum
    (``T_N``'s neighbours of ``μ``, and ``T_tail ≥ c_N − 2ê`` by Gershgorin).  So ``|μ − a| ≤
    2e|v_(N−1) v_N| + r²/g``.  Past the first row ``J`` with ``c_j − a ≥ 2ê`` (``ê = √2 |q|``
    ≥ every coupling), the tail's continued fraction ``B_j = e²_(j−1) / (c_j − a − B_(j+1))``
    stays in ``[0, ê]``, so ``|v_j / v_(j−1)| = e_(j−1) / (c_j − a − B_(j+1)) ≤ ê / (c_j − a
    − ê)`` and ``|v_n| ≤ Π_(j=J…n) ê / (c_j − a − ê)``.  ``inf`` when the tail starts past
    ``N − 1`` or the gap closes."""
    from scipy.linalg import eigvalsh_tridiagonal

    index, diag, couplings = mathieu_recurrence(kind, m, rows + 1)
    e = math.sqrt(2.0) * abs(q)
    if e == 0.0:
        return 0.0
    c = [r2 + s * q - a for r2, s in diag]
    J = next((j for j in range(1, rows) if all(c[i] >= 2 * e for i in range(j, rows + 1))),
             None)
    if J is None:
        return math.inf
    v = [1.0]
    for j in range(J, rows + 1):
        v.append(v[-1] * e / (c[j] - e))
    v_last, v_cut = v[-2], v[-1]  # |v_(N−1)|, |v_N|
    first = 2 * e * v_last * v_cut
    values = eigvalsh_tridiagonal(
        np.array([float(r2 + s * q) for r2, s in diag[:rows]]),
        np.array([math.sqrt(t) * abs(q) for t in couplings[: rows - 1]]))
    others = [abs(x - a) for i, x in enumerate(values) if i != index]
    others.append(diag[rows][0] + diag[rows][1] * q - 2 * e - a)
    gap = min(others) - first - 1e-9 * max(1.0, abs(a))  # the float64 eigenvalues' error
    if gap <= 0:
        return math.inf
    return first + e * e * (v_last**2 + v_cut**2) / gap


def mathieu_refined(kind: str, m: int, q: float, dps: int = 30) -> float:
    """``a_m(q)`` or ``b_m(q)`` to ``dps`` digits, fast: the float64 eigenvalue of
    :func:`mathieu_reference` refined by Newton steps on the determinant of the same
    truncated recurrence in mpmath (quadratic: 1e-15 → 1e-30 in one step; a third step
    checks it), as an ``mpf``."""
    import mpmath

    n = int(2 * math.sqrt(abs(q)) + 40)
    _, diag, couplings = mathieu_recurrence(kind, m, n)
    with mpmath.workdps(dps + 5):
        qq = mpmath.mpf(q)
        a = mpmath.mpf(mathieu_reference(kind, m, q))
        # NOTE: Newton's steps by hand, not numerics.newton: in mpmath at dps + 5 digits (the
        # one Newton works in float64), three of them, the third a check.
        for step in range(3):
            p_prev, dp_prev = mpmath.mpf(1), mpmath.mpf(0)
            p, dp = diag[0][0] + diag[0][1] * qq - a, mpmath.mpf(-1)
            for j in range(1, n):
                c = diag[j][0] + diag[j][1] * qq - a
                e2 = couplings[j - 1] * qq * qq
                p, p_prev, dp, dp_prev = (c * p - e2 * p_prev, p, c * dp - p - e2 * dp_prev, dp)
            delta = p / dp
            a -= delta
            if step == 2 and abs(delta) > mpmath.mpf(10) ** (-dps) * max(1, abs(a)):
                raise RuntimeError(f"mathieu_refined {kind}_{m}({q}): Newton did not converge")
        return +a


@dataclass(frozen=True)
class ModeOrbit:
    """A periodic orbit of a conservative system through its turning point: every coordinate
    at t = 0 (velocities zero), its period, its energy, and whether Newton converged."""

    start: np.ndarray
    period: float
    energy: float
    converged: bool


def system_rhs(system: object) -> Callable:
    """``(x', x'')`` of ``x'' + Lx + g(x) = 0`` (a :class:`derive.system.System`) for SciPy."""
    import sympy as sp

    d = system.size
    accel = sp.lambdify([system.coordinates],
                        [-(system.stiffness * sp.Matrix(system.coordinates))[i] - system.force[i]
                         for i in range(d)], "numpy")

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        return np.concatenate([z[d:], np.asarray(accel(z[:d]), dtype=float)])
    return rhs


def system_energy(system: object) -> Callable[[np.ndarray], float]:
    """The potential ``V(x) = ∫₀¹ xᵀM(L(sx) + g(sx)) ds`` (exact for a force with a potential:
    the energy at a turning point)."""
    import sympy as sp

    s = sp.Symbol("_s")
    x = sp.Matrix(system.coordinates)
    scaled = {c: s * c for c in system.coordinates}
    force = system.stiffness * x + sp.Matrix(system.force)
    integrand = sum(system.mass[i] * x[i] * force[i].xreplace(scaled) for i in range(system.size))
    V = sp.integrate(sp.expand(integrand), (s, 0, 1))
    return sp.lambdify([system.coordinates], V, "numpy")


STIFF_RATIO = 1e3
# NOTE: DOP853 steps at the fastest linear frequency: a slower mode's period costs this many
# times more steps than the fast one's (≥ 1e4 steps a period at rtol 1e-13): past it a shot
# orbit takes minutes to hours, and shooting is refused with the reason.


def check_shootable(system: object, why: str) -> None:
    """Refuse, in one line, to shoot the orbits of a stiff system (linear frequencies spread
    over more than :data:`STIFF_RATIO`): ``why`` names what needs the shots."""
    from ..errors import InputError

    squares = [float(x) for x in system.modes()]
    if min(squares) > 0 and math.sqrt(max(squares) / min(squares)) > STIFF_RATIO:
        ratio = math.sqrt(max(squares) / min(squares))
        raise InputError(f"system {system.text!r}: its linear frequencies span a ratio of "
                         f"{ratio:.3g} (stiff, above {STIFF_RATIO:g}): {why} shoots orbits "
                         "with DOP853, which would take ~ratio times a mode's period in steps "
                         "of the fastest; the series itself (lindstedt nnm, generate) is exact")


def mode_orbit(system: object, A: float, guess: np.ndarray, amplitude: int = 0,
               rtol: float = CYCLE_RTOL) -> ModeOrbit:
    """The periodic orbit through ``x_amplitude(0) = A`` with every velocity zero: Newton
    (:func:`numerics.newton.newton`, differences) on the other coordinates at t = 0 and the half
    period ``guess[-1]``, where every velocity vanishes again (a time-reversible orbit), each
    step shot by DOP853 at ``rtol``.  The coordinates are measured in units of ``A`` (Newton
    on ``x/A``, DOP853's absolute tolerance ``rtol·|A|/10``): the orbit's relative accuracy is
    the same at ``A = 1e-12`` as at ``A = 1`` (an absolute 1e-14 gave periods 1e-4 off there)."""
    from scipy.integrate import solve_ivp


    d = system.size
    rhs = system_rhs(system)
    scale = abs(A) or 1.0

    def start_of(u: np.ndarray) -> np.ndarray:
        return np.insert(u[:-1] * scale, amplitude, A)

    def residual(u: np.ndarray) -> np.ndarray:
        z0 = np.concatenate([start_of(u), np.zeros(d)])
        sol = solve_ivp(rhs, (0.0, u[-1]), z0, method="DOP853", rtol=rtol,
                        atol=rtol * scale / 10)
        return sol.y[d:, -1] / scale

    guess = np.asarray(guess, dtype=float)
    u, converged, _ = newton(residual, None, np.append(guess[:-1] / scale, guess[-1]),
                             tol=1e-12)
    start = start_of(u)
    return ModeOrbit(start, 2 * u[-1], float(system_energy(system)(start)), converged)


@dataclass(frozen=True, eq=False)
class Exchange:
    """The energy exchange of a resonant slow flow from amplitudes ``start`` and zero phases:
    its ``period`` (NaN: not two maxima of ``a₁`` within the steps allowed; inf: beyond
    floating point) and, where asked, the amplitudes ``a`` (shape ``(n, len(t))``) at slow
    times ``t`` from 0 over two exchanges (or as far as the steps went)."""

    start: tuple[float, ...]
    period: float
    t: np.ndarray
    a: np.ndarray


def energy_exchange(flow: object, start: Sequence[float], max_steps: int = EXCHANGE_MAX_STEPS,
                    samples: int = 0) -> Exchange:
    """:class:`Exchange` of a resonant slow flow (a :class:`derive.averaging.SlowFlow` of modes):
    the time between two successive maxima of the first mode's amplitude, by DOP853 on the
    averaged equations; ``samples`` > 0 also samples the amplitudes that many times, the
    integration carried on to a second exchange (within ``max_steps`` steps in all).  The step
    size may collapse where an amplitude nears 0 (its phase's rate ~ 1/a): the period is then
    NaN.

    The flow is homogeneous (``a_k'`` of degree d, ``φ_k'`` of degree d − 1 in the amplitudes,
    d the force's lowest degree): ``a(t) → λa(λ^{d−1}t)`` maps solutions to solutions.  So the
    flow is integrated from ``start / max(start)`` and its times divided by
    ``max(start)^{d−1}``: the same steps whatever the amplitude (integrated as given, a large
    start's fast exchange over a fixed span took ~ amplitude^{d−1} steps)."""
    import sympy as sp
    from scipy.integrate import DOP853
    from scipy.optimize import brentq

    n = len(flow.a)
    scale = max(start)
    rates = sp.lambdify([(*flow.a, *flow.phi)], [*flow.amplitude, *flow.phase], "numpy")
    y0 = np.array([*(a / scale for a in start), *([0.0] * n)])
    solver = DOP853(lambda t, y: rates(y), 0.0, y0, math.inf, rtol=1e-11, atol=1e-13)
    maxima: list[float] = []
    pieces = []  # each step's dense output, where the amplitudes are sampled
    before, end = rates(y0)[0], math.inf
    for _ in range(max_steps):
        solver.step()
        if solver.status != "running":
            break
        if samples:
            pieces.append(solver.dense_output())
        now = rates(solver.y)[0]
        if before >= 0 >= now and len(maxima) < 2:  # a₁' falls through 0 (solve_ivp's rule)
            dense = solver.dense_output()
            maxima.append(brentq(lambda t, dense=dense: rates(dense(t))[0], solver.t_old,
                                 solver.t, xtol=4 * np.finfo(float).eps))
            if len(maxima) == 2:
                end = 2 * maxima[1] - maxima[0]
        if solver.t >= end or (len(maxima) == 2 and not samples):
            break
        before = now
    period, shrink = math.nan, (flow.degree - 1) * math.log(scale)
    if len(maxima) == 2:
        log = math.log(maxima[1] - maxima[0]) - shrink
        period = math.exp(log) if log < 709 else math.inf
    if not pieces:
        return Exchange(tuple(start), period, np.zeros(0), np.zeros((n, 0)))
    last = min(end, pieces[-1].t_max)
    tau = np.linspace(0.0, last, samples)
    ends = np.array([piece.t_max for piece in pieces])
    which = np.minimum(np.searchsorted(ends, tau), len(pieces) - 1)
    a = np.array([pieces[k](t)[:n] for k, t in zip(which, tau, strict=True)]).T * scale
    return Exchange(tuple(start), period, tau * math.exp(-shrink), a)


def exchange_period(flow: object, start: Sequence[float],
                    max_steps: int = EXCHANGE_MAX_STEPS) -> float:
    """:class:`Exchange`'s period alone (no samples kept)."""
    return energy_exchange(flow, start, max_steps).period


def simulated_exchange_period(system: object, flow: object, start: Sequence[float],
                              periods: int = 3, rhs: Callable | None = None) -> float:
    """The same period from the full equations (DOP853 at 1e-11; ``rhs``: other equations of
    the same coordinates, ``(t, z) -> z'``): the first mode's energy ``(q₁'² + ω₁²q₁²)/2``
    (``q₁ = ψ₁·x``), averaged over each fast period, between its successive maxima;
    ``x(0) = Σ φ_k a_k``, every velocity zero."""
    import sympy as sp
    from scipy.integrate import solve_ivp
    from scipy.signal import find_peaks

    from ..derive.resonance import _shapes

    lam = sp.Integer(1) * flow.omega[0] ** 2
    _, left = _shapes(system, lam)
    psi = np.array([float(v) for v in left])
    x0 = sum(np.array([float(v) for v in shape]) * a for shape, a in
             zip(flow.shapes, start, strict=True))
    guess = exchange_period(flow, start)
    fast = 2 * np.pi / float(min(flow.omega))
    t_end = (periods + 0.5) * guess
    steps = int(t_end / fast) * 64
    t = np.linspace(0.0, t_end, steps)
    sol = solve_ivp(rhs or system_rhs(system), (0.0, t_end), [*x0, *np.zeros(system.size)],
                    method="DOP853", rtol=1e-11, atol=1e-14, t_eval=t)
    d = system.size
    w1 = float(flow.omega[0])
    energy = 0.5 * ((psi @ sol.y[d:]) ** 2 + w1**2 * (psi @ sol.y[:d]) ** 2)
    window = 64
    mean = energy[: len(energy) // window * window].reshape(-1, window).mean(axis=1)
    peaks, _ = find_peaks(mean, prominence=0.2 * (mean.max() - mean.min()))
    if len(peaks) < 2:
        return math.nan
    return float(np.mean(np.diff(peaks)) * fast)
