"""The one integrator: RK4 (a Richardson pair, or plain steps) of ``q̈ + g(q, q̇) = f cos ωt``
for any polynomial force table, compiled once; flows with escape detection, frequency
sweeps with their jumps, long simulations and their tone fits."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit

from ..errors import InputError

# --- periodic orbits of the driven oscillator: shooting and Floquet multipliers ---------------

@dataclass(frozen=True)
class ForceTable:
    """A polynomial force ``g(q, q̇) = Σ c_i q^(a_i) q̇^(b_i)`` of ``q̈ + g(q, q̇) = f cos ωt``
    (its linear part included), as the arrays the compiled integrator reads."""

    q_powers: np.ndarray  # a_i (int64)
    v_powers: np.ndarray  # b_i (int64)
    coefficients: np.ndarray  # c_i (float64)

    @staticmethod
    def of(terms: dict[tuple[int, int], float]) -> ForceTable:
        """From ``{(a, b): c}``; zero coefficients are dropped."""
        items = sorted((key, float(c)) for key, c in terms.items() if c != 0)
        return ForceTable(np.array([a for (a, _), _ in items], dtype=np.int64),
                          np.array([b for (_, b), _ in items], dtype=np.int64),
                          np.array([c for _, c in items], dtype=np.float64))

    @property
    def terms(self) -> dict[tuple[int, int], float]:
        """The force as ``{(a, b): c}``, the form :meth:`of` reads."""
        return {(int(a), int(b)): float(c) for a, b, c in
                zip(self.q_powers, self.v_powers, self.coefficients, strict=True)}

    @property
    def odd(self) -> bool:
        """``g(−q, −q̇) = −g(q, q̇)``: a periodic response to ``cos ωt`` holds odd harmonics."""
        return bool(np.all((self.q_powers + self.v_powers) % 2 == 1))

    @property
    def dissipative(self) -> bool:
        """A term odd in ``q̇``: the flow does not keep area (``det M ≠ 1`` in general), so
        stability asks every Floquet multiplier inside the unit circle."""
        return bool(np.any(self.v_powers % 2 == 1))

    @property
    def cubic(self) -> np.ndarray | None:
        """``(k₁, k₃, γ)`` when the force is ``k₁q + k₃q³ + γq̇`` (eq. 10.60's form, any of
        them zero): the integrator's unrolled fast path; else ``None``."""
        terms = self.terms
        if not set(terms) <= {(1, 0), (3, 0), (0, 1)}:
            return None
        return np.array([terms.get((1, 0), 0.0), terms.get((3, 0), 0.0),
                         terms.get((0, 1), 0.0)])

    @property
    def degree(self) -> int:
        """The highest total degree ``a + b`` of the terms (at least 1)."""
        return int(np.max(self.q_powers + self.v_powers, initial=1))


def duffing_table(eps: float, damping: float) -> ForceTable:
    """Eq. 10.60's force ``q + εq³ + q̇/Q`` as a :class:`ForceTable`."""
    return ForceTable.of({(1, 0): 1.0, (3, 0): eps, (0, 1): damping})


@njit(cache=True)
def _power(x: float, n: int) -> float:
    """``x**n`` for an integer ``n ≥ 0`` by multiplication (the low powers unrolled)."""
    if n == 0:
        return 1.0
    if n == 1:
        return x
    if n == 2:
        return x * x
    if n == 3:
        return x * x * x
    out = x * x * x
    for _ in range(n - 3):
        out *= x
    return out


@njit(cache=True)
def _table_force(q: float, p: float, qp: np.ndarray, vp: np.ndarray,
                 cs: np.ndarray) -> tuple[float, float, float]:
    """``g = Σ c q^a p^b`` and its partial derivatives ``∂g/∂q``, ``∂g/∂p``."""
    g, gq, gp = 0.0, 0.0, 0.0
    for i in range(cs.size):
        a, b, c = qp[i], vp[i], cs[i]
        qa, pb = _power(q, a), _power(p, b)
        g += c * qa * pb
        if a > 0:
            gq += c * a * _power(q, a - 1) * pb
        if b > 0:
            gp += c * b * qa * _power(p, b - 1)
    return g, gq, gp


@njit(cache=True)
def _rhs(t: float, y: np.ndarray, qp: np.ndarray, vp: np.ndarray, cs: np.ndarray,
         cubic: np.ndarray | None, force: float, omega: float, out: np.ndarray) -> None:
    """``q̈ = f cos ωt − Σ c q^a q̇^b`` and its variational equation:
    y = (q, p, M11, M21, M12, M22).  ``cubic``: ``None``, or ``(k₁, k₃, γ)`` when the table
    is ``k₁q + k₃q³ + γq̇`` (:attr:`ForceTable.cubic`): then the force is evaluated unrolled
    (numba compiles the kernel once for each case and drops the branch not taken)."""
    q, p = y[0], y[1]
    if cubic is not None:  # the fast path (eq. 10.60)
        g = cubic[0] * q + cubic[1] * q * q * q + cubic[2] * p
        gq, gp = cubic[0] + 3.0 * cubic[1] * q * q, cubic[2]
    else:
        g, gq, gp = _table_force(q, p, qp, vp, cs)
    out[0] = p
    out[1] = force * np.cos(omega * t) - g
    for col in range(2):
        u, w = y[2 + 2 * col], y[3 + 2 * col]
        out[2 + 2 * col] = w
        out[3 + 2 * col] = -gq * u - gp * w


NO_TERMS = np.zeros((0, 4))
# NOTE: the ``extra`` rows of :func:`_rk4_step` when there are none.


@njit(cache=True, inline="always")
def _field(t: float, y: np.ndarray, qp: np.ndarray, vp: np.ndarray, cs: np.ndarray,
           cubic: np.ndarray | None, force: float, omega: float, beta: float,
           extra: np.ndarray, out: np.ndarray) -> None:
    """:func:`_rhs` with the drive's phase ``ωt + βt²/2`` (a linear chirp; ``β = 0`` leaves
    ``ωt`` exact) and the time-dependent terms ``extra``: each row ``(a, c, ν, φ)`` adds
    ``c q^a cos(νt + φ)`` to ``q̈`` — ``a = 0`` another drive, ``a = 1`` a parametric
    stiffness (carried into the variational columns)."""
    _rhs(t, y, qp, vp, cs, cubic, force, omega + 0.5 * beta * t, out)
    for i in range(extra.shape[0]):
        w = extra[i, 1] * np.cos(extra[i, 2] * t + extra[i, 3])
        if extra[i, 0] == 0.0:
            out[1] += w
        else:
            for j in range(1, 6, 2):
                out[j] += w * y[j - 1]


@njit(cache=True, inline="always")
def _rk4_step(t: float, h: float, y: np.ndarray, qp: np.ndarray, vp: np.ndarray,
              cs: np.ndarray, cubic: np.ndarray | None, force: float, omega: float,
              beta: float, extra: np.ndarray, k1: np.ndarray, k2: np.ndarray, k3: np.ndarray,
              k4: np.ndarray, tmp: np.ndarray) -> None:
    """One classical RK4 step of ``h`` from ``t``, in place on ``y = (q, p, M11, M21, M12,
    M22)`` (the state and the monodromy columns) for ``q̈ + Σ c q^a q̇^b = f cos(ωt + βt²/2)
    + extra`` (:func:`_field`): every integrator of this module steps with it.
    ``k1 … k4, tmp``: work arrays of six entries (no temporaries in the loop)."""
    # NOTE: six entries always, even where the columns are not read: loops of a constant
    # length unroll (the flow 0.76 ms with y.size, 0.58 ms with 6).
    _field(t, y, qp, vp, cs, cubic, force, omega, beta, extra, k1)
    for j in range(6):
        tmp[j] = y[j] + 0.5 * h * k1[j]
    _field(t + 0.5 * h, tmp, qp, vp, cs, cubic, force, omega, beta, extra, k2)
    for j in range(6):
        tmp[j] = y[j] + 0.5 * h * k2[j]
    _field(t + 0.5 * h, tmp, qp, vp, cs, cubic, force, omega, beta, extra, k3)
    for j in range(6):
        tmp[j] = y[j] + h * k3[j]
    _field(t + h, tmp, qp, vp, cs, cubic, force, omega, beta, extra, k4)
    for j in range(6):
        y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])


@njit(cache=True)
def _rk4(y0: np.ndarray, t0: float, t1: float, steps: int, qp: np.ndarray, vp: np.ndarray,
         cs: np.ndarray, cubic: np.ndarray | None, force: float, omega: float, samples: int,
         bound: float, extra: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Classical RK4 with ``steps`` steps on ``q̈ + Σ c q^a q̇^b = f cos ωt`` (the table
    ``qp, vp, cs``, and the rows ``extra`` of :func:`_field`); returns the end state,
    ``samples`` equispaced values of q on [t0, t1) (``steps`` must be a multiple of
    ``samples``) and the time the trajectory escaped (−1 if it did not): ``|q| > bound``
    moving outward (``q q̇ ≥ 0``), where it stops, the state and the samples not reached NaN."""
    h = (t1 - t0) / steps
    y = y0.copy()
    k1, k2, k3, k4 = np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    tmp = np.empty(6)
    qs = np.empty(samples)
    every = steps // samples
    escaped = -1.0
    for i in range(steps):
        if i % every == 0:
            qs[i // every] = y[0]
        t = t0 + i * h
        _rk4_step(t, h, y, qp, vp, cs, cubic, force, omega, 0.0, extra, k1, k2, k3, k4, tmp)
        if abs(y[0]) > bound and y[0] * y[1] >= 0.0:
            escaped = t + h
            for j in range(i // every + 1, samples):
                qs[j] = np.nan
            y[:] = np.nan
            break
    return y, qs, escaped


STEPS_PER_PERIOD = 4096
# NOTE: RK4 at 4096 and 8192 steps per period, Richardson-combined (error ∝ h⁴ cancels):
# the remaining O(h⁶) is ~1e-13 for the amplitudes of the notes' table.


def escape_bound(eps: float, force: float) -> float:
    """The largest ``|q|`` any periodic orbit reaches, and past which nothing returns: ``inf``
    for ``ε ≥ 0``; for a softening spring the positive root of ``|ε|x³ − x − |f| = 0`` (just
    beyond the barrier ``1/√−ε``).

    At the largest ``|q|`` of an orbit ``q̇ = 0`` and ``q q̈ ≤ 0``: ``q² (|ε|q² − 1) ≤ |f q|``.
    Past the root, ``q q̈ > 0`` wherever ``q̇ = 0``, so a trajectory there moving outward
    (``q q̇ ≥ 0``) never turns back: ``|q|`` grows without bound (it escapes the well)."""
    if not eps < 0:
        return math.inf
    k, f = -float(eps), abs(float(force))
    x = max(math.sqrt(2 / k), (2 * f / k) ** (1 / 3))  # right of the root: g(x) ≥ 0
    # NOTE: Newton's method by hand, not numerics.newton: integrate stands above newton in the
    # package's stage list (shooting, below both, imports them), so it cannot import it.
    for _ in range(100):  # Newton on the convex g from the right: monotone
        step = (k * x**3 - x - f) / (3 * k * x * x - 1)
        x -= step
        if step <= 1e-15 * x:
            break
    return x


def flow_table(table: ForceTable, force: float, omega: float, y0: np.ndarray, period: float,
               samples: int = 64, steps: int | None = None,
               bound: float = math.inf, extra: np.ndarray = NO_TERMS
               ) -> tuple[np.ndarray, np.ndarray, float]:
    """One period of ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the table; the time-dependent rows
    ``extra`` of :func:`_field` added) from ``y0`` with its monodromy columns, ``samples``
    values of q over it and the time the trajectory escaped past ``bound`` (−1 if it did not;
    the state and the samples from there are NaN): Richardson-extrapolated from two RK4 step
    sizes, or plain RK4 with ``steps`` steps."""
    state = np.concatenate([np.asarray(y0, dtype=float), [1.0, 0.0, 0.0, 1.0]])
    bound = float(bound)
    args = (table.q_powers, table.v_powers, table.coefficients, table.cubic, float(force),
            float(omega))
    extra = np.asarray(extra, dtype=float).reshape(-1, 4)
    if steps is not None:
        return _rk4(state, 0.0, period, steps, *args, samples, bound, extra)
    coarse, qc, tc = _rk4(state, 0.0, period, STEPS_PER_PERIOD, *args, samples, bound, extra)
    fine, qf, tf = _rk4(state, 0.0, period, 2 * STEPS_PER_PERIOD, *args, samples, bound, extra)
    escaped = min((t for t in (tc, tf) if t >= 0), default=-1.0)
    return fine + (fine - coarse) / 15, qf + (qf - qc) / 15, escaped


def flow_escape(y0: np.ndarray, period: float, eps: float, force: float, omega: float,
                damping: float, samples: int = 64, steps: int | None = None,
                bound: float = math.inf) -> tuple[np.ndarray, np.ndarray, float]:
    """:func:`flow` and the time the trajectory escaped past ``bound`` (−1 if it did not; the
    state and the samples from there are NaN)."""
    return flow_table(duffing_table(eps, damping), force, omega, y0, period, samples, steps,
                      bound)


def flow(y0: np.ndarray, period: float, eps: float, force: float, omega: float,
         damping: float, samples: int = 64,
         steps: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """State after one period (with monodromy columns) and q sampled over it, Richardson-
    extrapolated from two RK4 step sizes; or plain RK4 with ``steps`` steps (a multiple of
    ``samples``) when given.  NaN where the trajectory escaped the well
    (:func:`escape_bound`)."""
    end, qs, _ = flow_escape(y0, period, eps, force, omega, damping, samples, steps,
                             escape_bound(eps, force))
    return end, qs


@njit(cache=True)
def _sweep(qp: np.ndarray, vp: np.ndarray, cs: np.ndarray, cubic: np.ndarray | None,
           force: float, omega0: float, omega1: float, periods: int, steps: int,
           bound: float) -> tuple[np.ndarray, np.ndarray]:
    """RK4 on ``q̈ + Σ c q^a q̇^b = f cos(ω₀t + βt²/2)`` (the table ``qp, vp, cs``; ``cubic``
    as in :func:`_rhs`) through a linear frequency sweep ``ω(t) = ω₀ + βt`` of ``periods``
    drive periods; per period: the mean ω and max |q|.  Where ``|q|`` passes ``bound`` moving
    outward (``q q̇ ≥ 0``) the trajectory has escaped: it stops at the end of that period,
    the later ones' max |q| NaN."""
    mean = 0.5 * (omega0 + omega1)
    duration = periods * 2 * np.pi / mean
    beta = (omega1 - omega0) / duration
    h = 2 * np.pi / (max(omega0, omega1) * steps)
    n = int(duration / h) + 1
    h = duration / n
    q, p, t = 0.0, 0.0, 0.0
    omegas = np.zeros(periods)
    amps = np.zeros(periods)
    counts = np.zeros(periods)
    y, tmp = np.zeros(6), np.zeros(6)  # (q, p) and a zero variational part
    k1, k2, k3, k4 = np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    escaped = periods
    for _ in range(n):
        phase = omega0 * t + 0.5 * beta * t * t
        k = min(int(phase / (2 * np.pi)), periods - 1)
        if k > escaped:  # the period of the escape is complete: stop
            for j in range(k, periods):  # ω at the middle of the periods not reached
                amps[j] = np.nan
                omegas[j] = np.sqrt(max(omega0**2 + 4 * np.pi * beta * (j + 0.5), 0.0))
                counts[j] = 1
            break
        amps[k] = max(amps[k], abs(q))
        omegas[k] += omega0 + beta * t
        counts[k] += 1
        _rk4_step(t, h, y, qp, vp, cs, cubic, force, omega0, beta, NO_TERMS, k1, k2, k3, k4,
                  tmp)
        q, p = y[0], y[1]
        t += h
        if escaped == periods and abs(q) > bound and q * p >= 0.0:
            escaped = k
            amps[k] = max(amps[k], abs(q))
    return omegas / np.maximum(counts, 1), amps


@dataclass(frozen=True)
class Sweep:
    """A simulated slow sweep: amplitude per drive period and where it jumps."""

    omega: np.ndarray
    amplitude: np.ndarray
    jump: float | None  # ω where the amplitude crosses between the branches, if it jumps
    resolution: float = float("nan")  # the change of ω per drive period (the sweep's step)
    escape: float | None = None  # ω where a softening spring left its well (then no jump)


SWEEP_STEPS = 64
# NOTE: RK4 steps per drive period; the amplitude per period needs ~1e-6, not 1e-12.
JUMP_RATIO = 2.0
JUMP_WINDOW = 50
# NOTE: the amplitude changing by 2× within 50 drive periods (a few damping times at the
# Q of interest, a small step in ω at the default sweep rate) is a jump, not a slope.


def sweep(eps: float, force: float, damping: float, omega_from: float, omega_to: float,
          periods: int = 10_000) -> Sweep:
    """Sweep the drive frequency slowly from ``omega_from`` to ``omega_to`` (compiled RK4): the
    amplitude per drive period, the jump between branches if any, or — a softening spring
    driven over its barrier ``|q| = 1/√−ε`` — the ω where it escapes (amplitudes NaN from there,
    no jump reported)."""
    barrier = 1 / np.sqrt(-eps) if eps < 0 else np.inf  # the potential's maxima, |q| = 1/√−ε
    return sweep_table(duffing_table(eps, damping), force, omega_from, omega_to, periods,
                       barrier, escape_bound(eps, force))


def sweep_table(table: ForceTable, force: float, omega_from: float, omega_to: float,
                periods: int = 10_000, barrier: float = math.inf,
                bound: float = math.inf) -> Sweep:
    """:func:`sweep` of ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the polynomial ``table``): an
    amplitude past ``barrier``, or a trajectory past ``bound`` moving outward (where the
    integration stops), or one that overflows, is an escape."""
    omegas, amps = _sweep(table.q_powers, table.v_powers, table.coefficients, table.cubic,
                          float(force), float(omega_from), float(omega_to), periods,
                          SWEEP_STEPS, float(bound))
    step = abs(omega_to - omega_from) / periods
    with np.errstate(invalid="ignore"):
        out = ~np.isfinite(amps) | (amps > barrier)
    if out.any():  # over the barrier the orbit runs off to infinity: no branch to jump to
        first = int(np.argmax(out))
        amps = np.where(np.arange(amps.size) < first, amps, np.nan)
        return Sweep(omegas, amps, None, step, float(omegas[first]))
    skip = periods // 20  # the start-up transient
    a = amps[skip:]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.maximum(a[JUMP_WINDOW:] / a[:-JUMP_WINDOW], a[:-JUMP_WINDOW] / a[JUMP_WINDOW:])
    hits = np.nonzero(ratio > JUMP_RATIO)[0]
    if not hits.size:
        return Sweep(omegas, amps, None, step)
    # the jump is where the amplitude crosses the geometric mean of the two branches' amplitudes
    # around it, inside the window that detected it (interpolated in log amplitude)
    i = int(hits[0])
    seg = np.log(a[i:i + JUMP_WINDOW + 1])
    middle = 0.5 * (seg[0] + seg[-1])
    k = int(np.argmax(np.sign(seg - middle) != np.sign(seg[0] - middle)))
    frac = (middle - seg[k - 1]) / (seg[k] - seg[k - 1]) if k > 0 and seg[k] != seg[k - 1] else 0
    w0, w1 = omegas[skip + i + k - 1], omegas[skip + i + k]
    return Sweep(omegas, amps, float(w0 + frac * (w1 - w0)), step)


@njit(cache=True)
def _simulate(qp: np.ndarray, vp: np.ndarray, cs: np.ndarray, cubic: np.ndarray | None,
              forces: np.ndarray, omegas: np.ndarray, h: float, n_skip: int, n_keep: int,
              every: int, q0: float, p0: float) -> np.ndarray:
    """RK4 (:func:`_rk4_step`) on ``q̈ + Σ c q^a q̇^b = Σ f_i cos ω_i t`` from (q0, p0); after
    ``n_skip`` steps keep q every ``every`` steps, ``n_keep`` values."""
    extra = np.zeros((forces.size - 1, 4))  # the drives after the first: rows (0, f, ω, 0)
    extra[:, 1], extra[:, 2] = forces[1:], omegas[1:]
    y, t = np.array([q0, p0, 0.0, 0.0, 0.0, 0.0]), 0.0  # no columns: they stay 0
    k1, k2, k3, k4, tmp = np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    out = np.empty(n_keep)
    total = n_skip + n_keep * every
    for i in range(total):
        if i >= n_skip and (i - n_skip) % every == 0:
            out[(i - n_skip) // every] = y[0]
        _rk4_step(t, h, y, qp, vp, cs, cubic, forces[0], omegas[0], 0.0, extra, k1, k2, k3, k4,
                  tmp)
        t += h
    return out


MAX_STEPS = 100_000_000
MAX_FIT_ENTRIES = 30_000_000
# NOTE: 1e8 compiled RK4 steps are ~20 s with four drives; 3e7 entries (240 MB) hold the
# least-squares fit of four drives' 228 tones at drive frequencies up to ~2.5.


@dataclass(frozen=True)
class ToneFit:
    """The simulated steady state's amplitude at each frequency, its standard error, and the
    rms of what the fit leaves (every tone not asked for counts as noise)."""

    amplitudes: np.ndarray
    uncertainty: np.ndarray
    rms_residual: float
    mean: float = math.nan  # the steady state's mean (the constant of the fit)


def steady_state_amplitudes(table: ForceTable, forces: list[float],
                            omegas: list[float], frequencies: list[float],
                            settle: float | None = None, window: float = 2000.0,
                            initial: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """The amplitudes of :func:`steady_state_fit`."""
    return steady_state_fit(table, forces, omegas, frequencies, settle, window,
                            initial).amplitudes


def steady_state_fit(table: ForceTable, forces: list[float],
                     omegas: list[float], frequencies: list[float],
                     settle: float | None = None, window: float = 2000.0,
                     initial: tuple[float, float] = (0.0, 0.0)) -> ToneFit:
    """Amplitudes of the simulated steady state of ``q̈ + g(q, q̇) = Σ f_i cos ω_i t`` (``g``
    the polynomial ``table``; eq. 10.60's is :func:`duffing_table`) at ``frequencies`` (least
    squares on cos/sin over a long window after the transients, ``40/γ`` time units for the
    linear damping ``γq̇``, have died out), starting
    from ``initial`` = (q, q̇) — which decides the attractor where several coexist — with
    their standard errors: the covariance ``σ²(XᵀX)⁻¹`` of the fit, ``σ`` the rms residual,
    carried to each amplitude ``√(c² + s²)`` (``√((var c + var s)/2)`` where it is 0).

    NaN amplitudes when the simulated orbit overflows (it escapes to infinity: a softening
    spring driven over its barrier, or RK4 unstable at that amplitude).  :class:`InputError`
    when the simulation would exceed :data:`MAX_STEPS` or its fit :data:`MAX_FIT_ENTRIES`."""
    damping = table.terms.get((0, 1), 0.0)
    if settle is None:
        if not damping > 0:
            raise InputError("damping 0 (Q inf): the transients never die out, there is no "
                             "steady state to settle into")
        settle = 40.0 / damping
    fastest = max(max(omegas), max(frequencies))
    every = 4
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        h = 2 * np.pi / (np.float64(fastest) * 64)
        steps = (settle + window) / h
        entries = window / (h * every) * (2 * len(frequencies) + 1)
    if not steps <= MAX_STEPS:
        if settle > window:
            raise InputError(f"Q {1 / damping:g}: the transients die out over 40Q = {settle:.3g} "
                             f"time units, {steps:.2g} RK4 steps at 64 a period of frequency "
                             f"{fastest:g}; the limit is {MAX_STEPS:.0e} steps")
        raise InputError(f"frequency {fastest:g} (a drive or its tone): 64 RK4 steps a period "
                         f"over {settle + window:g} time units is {steps:.2g} steps; the limit "
                         f"is {MAX_STEPS:.0e}")
    if not entries <= MAX_FIT_ENTRIES:
        raise InputError(f"frequency {fastest:g} with {len(frequencies)} tones: the fit over "
                         f"{window:g} time units needs {entries:.2g} matrix entries; the limit is "
                         f"{MAX_FIT_ENTRIES:.0e}")
    n_keep = int(window / (h * every))
    with np.errstate(over="ignore", invalid="ignore"):
        q = _simulate(table.q_powers, table.v_powers, table.coefficients, table.cubic,
                      np.array(forces, float), np.array(omegas, float), float(h),
                      int(settle / h), n_keep, every, float(initial[0]), float(initial[1]))
    if not np.all(np.isfinite(q)):
        nan = np.full(len(frequencies), np.nan)
        return ToneFit(nan, nan, math.nan)
    t = settle + np.arange(n_keep) * h * every
    basis = [np.ones_like(t)]
    for nu in frequencies:
        basis += [np.cos(nu * t), np.sin(nu * t)]
    X = np.column_stack(basis)
    coef, *_ = np.linalg.lstsq(X, q, rcond=None)
    residual = q - X @ coef
    sigma2 = float(residual @ residual) / max(len(q) - X.shape[1], 1)
    cov = sigma2 * np.linalg.pinv(X.T @ X)
    c, s = coef[1::2], coef[2::2]
    var_c, var_s = np.diag(cov)[1::2], np.diag(cov)[2::2]
    cov_cs = np.diag(cov, 1)[1::2]
    amp = np.hypot(c, s)
    with np.errstate(invalid="ignore", divide="ignore"):
        var = np.where(amp > 0, (c * c * var_c + s * s * var_s + 2 * c * s * cov_cs)
                       / np.where(amp > 0, amp * amp, 1.0), (var_c + var_s) / 2)
    return ToneFit(amp, np.sqrt(np.maximum(var, 0.0)), math.sqrt(sigma2), float(coef[0]))


# --- a system's polynomial force: x_i'' + g_i(x, x') = d_i f cos ωt ---------------------------

@dataclass(frozen=True)
class PolynomialField:
    """The force ``g_i(x, ẋ) = Σ c x₁^a₁ … x_n^a_n ẋ₁^b₁ … ẋ_n^b_n`` of each equation of
    ``ẍ_i + g_i(x, ẋ) = d_i f cos ωt`` (the linear part included) as arrays: one row per term,
    its exponents ``(a₁ … a_n, b₁ … b_n)``, its equation and its coefficient.  One coordinate
    (``n = 1``) is :class:`ForceTable`'s force."""

    exponents: np.ndarray  # (terms, 2n) int64
    rows: np.ndarray  # (terms,) int64: the equation of each term
    coefficients: np.ndarray  # (terms,) float64
    size: int  # n

    @staticmethod
    def of(equations: tuple[dict[tuple[int, ...], float], ...]) -> PolynomialField:
        """From one ``{exponents: c}`` per equation (zero coefficients dropped)."""
        n = len(equations)
        items = [(i, tuple(int(e) for e in key), float(c)) for i, eq in enumerate(equations)
                 for key, c in sorted(eq.items()) if c != 0]
        if any(len(key) != 2 * n for _, key, _ in items):
            raise ValueError(f"PolynomialField: each term needs {2 * n} exponents")
        return PolynomialField(np.array([key for _, key, _ in items],
                                        dtype=np.int64).reshape(-1, 2 * n),
                               np.array([i for i, _, _ in items], dtype=np.int64),
                               np.array([c for _, _, c in items], dtype=np.float64), n)

    @property
    def odd(self) -> bool:
        """``g(−x, −ẋ) = −g(x, ẋ)``: a response to ``cos ωt`` holds odd harmonics only."""
        return bool(np.all(self.exponents.sum(axis=1) % 2 == 1))

    @property
    def degree(self) -> int:
        """The highest total degree of the terms (at least 1)."""
        return int(np.max(self.exponents.sum(axis=1), initial=1))

    @cached_property
    def _terms(self) -> list[tuple[int, float, list[tuple[int, int]]]]:
        """Each term as ``(equation, c, [(variable, exponent) …])`` over its variables."""
        return [(int(i), float(c), [(j, int(e)) for j, e in enumerate(key) if e])
                for key, i, c in zip(self.exponents, self.rows, self.coefficients, strict=True)]

    def evaluate(self, X: np.ndarray, V: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``g``, ``∂g_i/∂x_j`` and ``∂g_i/∂ẋ_j`` at the states ``X``, ``V`` (``(n, S)``):
        arrays ``(n, S)``, ``(n, n, S)``, ``(n, n, S)``; powers by products."""
        n = self.size
        Z = np.concatenate([X, V])
        powers = []
        for j, top in enumerate(np.max(self.exponents, axis=0, initial=0)):
            p = [None, Z[j]]
            while len(p) <= top:
                p.append(p[-1] * Z[j])
            powers.append(p)
        g = np.zeros_like(X)
        dg = np.zeros((n, 2 * n, X.shape[1]))
        for i, c, used in self._terms:
            factors = [powers[j][e] for j, e in used]
            mono = c * factors[0]
            for f in factors[1:]:
                mono = mono * f
            g[i] += mono
            for k, (j, e) in enumerate(used):
                part = c * e if e == 1 else (c * e) * powers[j][e - 1]
                for m, f in enumerate(factors):
                    if m != k:
                        part = part * f
                dg[i, j] += part
        return g, dg[:, :n], dg[:, n:]


@njit(cache=True)
def _system_field(t: float, y: np.ndarray, exponents: np.ndarray, rows: np.ndarray,
                  cs: np.ndarray, drive: np.ndarray, omega: float, n: int) -> np.ndarray:
    """``(ẋ, ẍ, Φ̇)`` of ``ẍ_i + g_i(x, ẋ) = d_i cos ωt`` (the field's arrays) and its
    variational equation ``Φ̇ = [[0, I], [−∂g/∂x, −∂g/∂ẋ]] Φ``, ``Φ`` column-major after the
    state ``y[:2n]``."""
    m = 2 * n
    out = np.zeros_like(y)
    A = np.zeros((m, m))
    for i in range(n):
        out[i] = y[n + i]
        out[n + i] = drive[i] * np.cos(omega * t)
        A[i, n + i] = 1.0
    for r in range(cs.size):
        i = rows[r]
        mono = cs[r]
        for j in range(m):
            mono *= _power(y[j], exponents[r, j])
        out[n + i] -= mono
        for j in range(m):
            e = exponents[r, j]
            if e == 0:
                continue
            part = cs[r] * e
            for k in range(m):
                part *= _power(y[k], exponents[r, k] - (1 if k == j else 0))
            A[n + i, j] -= part
    for col in range(m):
        for i in range(m):
            s = 0.0
            for k in range(m):
                s += A[i, k] * y[m + col * m + k]
            out[m + col * m + i] = s
    return out


@njit(cache=True)
def _system_accel(t: float, y: np.ndarray, exponents: np.ndarray, rows: np.ndarray,
                  cs: np.ndarray, drive: np.ndarray, omega: float, n: int) -> np.ndarray:
    """``(ẋ, ẍ)`` of ``ẍ_i + g_i(x, ẋ) = d_i cos ωt``, the state alone."""
    out = np.empty(2 * n)
    for i in range(n):
        out[i] = y[n + i]
        out[n + i] = drive[i] * np.cos(omega * t)
    for r in range(cs.size):
        mono = cs[r]
        for j in range(2 * n):
            mono *= _power(y[j], exponents[r, j])
        out[n + rows[r]] -= mono
    return out


@njit(cache=True)
def _system_record(y0: np.ndarray, omega: float, transient: int, periods: int, samples: int,
                   substeps: int, exponents: np.ndarray, rows: np.ndarray, cs: np.ndarray,
                   drive: np.ndarray, n: int) -> np.ndarray:
    """RK4 of :func:`_system_accel`, ``samples·substeps`` steps a period, the state kept
    ``samples`` times a period after ``transient`` periods: ``(2n, periods·samples + 1)``."""
    T = 2 * np.pi / omega
    steps = samples * substeps
    h = T / steps
    out = np.empty((2 * n, periods * samples + 1))
    y = y0.copy()
    k = 0
    for p in range(transient + periods):
        for s in range(steps):
            if p >= transient and s % substeps == 0:
                out[:, k] = y
                k += 1
            t = (p * steps + s) * h
            k1 = _system_accel(t, y, exponents, rows, cs, drive, omega, n)
            k2 = _system_accel(t + h / 2, y + h / 2 * k1, exponents, rows, cs, drive, omega, n)
            k3 = _system_accel(t + h / 2, y + h / 2 * k2, exponents, rows, cs, drive, omega, n)
            k4 = _system_accel(t + h, y + h * k3, exponents, rows, cs, drive, omega, n)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            if not np.all(np.isfinite(y)):
                out[:, :] = np.nan
                return out
    out[:, k] = y
    return out


def record_system(field: PolynomialField, drive: np.ndarray, omega: float, start: np.ndarray,
                  transient: int, periods: int, samples: int, substeps: int = 8
                  ) -> np.ndarray | None:
    """The state ``(x, ẋ)`` of ``ẍ_i + g_i(x, ẋ) = d_i cos ωt`` from ``start`` at ``t = 0``
    by the compiled RK4 (``samples·substeps`` steps a drive period: bounded by periods, not by
    the clock), kept ``samples`` times a period over ``periods`` periods after ``transient``:
    ``(2n, periods·samples + 1)``, a period's start every ``samples`` columns (the
    stroboscopic points); None where it leaves double precision."""
    out = _system_record(np.asarray(start, dtype=float), float(omega), int(transient),
                         int(periods), int(samples), int(substeps), field.exponents,
                         field.rows, field.coefficients, np.asarray(drive, dtype=float),
                         field.size)
    return out if np.all(np.isfinite(out)) else None
