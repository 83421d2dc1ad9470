"""Where the period-1 response of a driven, damped oscillator or system stops being the whole
story: the bifurcations along every traced branch of the balance — folds (a real Floquet
multiplier through +1), period doublings (a real multiplier through −1) and Neimark–Sacker
points (a complex pair leaving the unit circle), each refined on the branch by secant on
``|μ| − 1`` — and, where no period-1 orbit is stable or a branch loses stability by
Neimark–Sacker, the attractor a simulation from the unstable orbit settles on: period-k,
quasi-periodic (a second frequency incommensurate with ω) or other (chaotic), its spectral
lines and amplitude range."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..numerics.floquet import variational_multipliers
from ..numerics.integrate import PolynomialField, record_system
from ..numerics.newton import secant
from .continuation import Continuation, _corrector, _tangent, fold_point
from .polynomial import PolynomialBalance

FLOQUET_SAMPLES = 512
# NOTE: samples per period of the variational equation about each balance orbit (times the
# power of two above ω0,max/ω): RK4 of 256 and 128 steps, Richardson-combined; |λ| to ~1e-9 on
# the suite's systems (checked against the linear system's exact e^(−cT/2)).
NEUTRAL = 1 + 1e-8
# NOTE: outside the unit circle where |μ| > 1 + 1e-8: a neutral direction (an undamped
# coordinate the drive leaves at rest, |μ| = 1 to rounding) is not a crossing.
COMPLEX = 1e-9
# NOTE: a multiplier is one of a complex pair where |Im μ| > 1e-9 |μ| (LAPACK gives a real
# matrix's real eigenvalues with Im exactly 0; a pair about to meet on the real axis has
# |Im μ| ~ √(distance to the collision), far above rounding).
REFINE_STEPS = 30
# NOTE: secant (Illinois) steps on |μ| − 1 between two points of the curve, each a corrector
# onto the curve and one monodromy (~5 ms on a 2-DOF system); |μ| − 1 to 1e-10 in ~6–10.
TRANSIENT_PERIODS = 300
RECORD_PERIODS = 256
RECORD_SAMPLES = 32
RECORD_SUBSTEPS = 8
RESOLVED_STEP = 0.15
# NOTE: RK4 at 32 × 8 steps a drive period; where the motion's rate max|ẋ|/max|x| times the
# step passes 0.15 (its local frequency at the turning points ~2.5 times more), RK4's own
# damping, ~(ωh)⁶/144 a step, rivals a physical one: a negative damping pumping x1 to
# |x1| = 26 at ω ≈ 13 looked bounded and "chaotic" when it grows without end.
# NOTE: one simulation per interval: 300 drive periods of transient (a torus born at a
# Neimark–Sacker point attracts at the rate of the damping, |μ| ≈ e^(−cT/2) ≈ 0.95 a period
# for c = 0.05 near ω = 2: 1e-7 after 300), then 256 periods at 32 samples each (RK4 of 256
# steps a period; the lines agree with DOP853 at rtol 1e-9 to 1e-7): the
# spectrum's bins are ω/256 apart up to 16ω; ~0.5 s on a 2-DOF system.
PUSH = 1e-3
# NOTE: the unstable orbit's state pushed by 1e-3 of its size (in every coordinate and
# velocity alike): it leaves along its unstable directions within ~log(1e3)/log|μ| periods.
MAX_RUNS = 6
# NOTE: at most six simulations (the intervals in order of ω): each ~0.5 s.
PERIOD_TOLERANCE = 1e-5
MAX_PERIOD = 32
# NOTE: period-k where the stroboscopic points repeat after k ≤ 32 periods to 1e-5 of the
# attractor's size throughout the record (a torus's points never do; a locked torus of a
# longer period is reported by its spectrum, its two frequencies commensurate).
LINES = 8
LINE_FLOOR = 1e-4
# NOTE: the spectral lines reported per coordinate: the 8 largest local maxima of the Hann-
# windowed spectrum above 1e-4 of the largest, each frequency refined by the parabola through
# the log-magnitude of three bins (~1e-3 of a bin for a clean line).
GROWTH = 1.1
# NOTE: "growing" (no bounded steady state reached) where the largest coordinate's range grows
# from each quarter of the record to the next and the last is 10 % above the first: a
# negative damping that the nonlinear force does not saturate pumps without end (such a record
# was called chaotic); a chaotic attractor's range does not climb steadily.
COMBINATIONS = (5, 8)
QUASI_POWER = 0.995
# NOTE: quasi-periodic where 99.5 % of the windowed spectrum's power lies within two bins of
# the lines m ω + n ν (0 ≤ m ≤ 5, |n| ≤ 8; ν the largest line off the harmonics of ω): a
# chaotic attractor spreads its power over the band.


FLOQUET_SAMPLE_SECONDS = (1.5e-6, 2.5e-8, 2048, 0.6)
# NOTE: CPU seconds of one point's multipliers per sample of its period, fixed + per unknown
# (the linearization on the samples, then the 2n-dimensional variational RK4), times
# (samples/2048)^0.6 above 2048 (the bases of the samples no longer in cache): measured by
# time.process_time beside a test run on 2 cores, 1.5 µs at 31 unknowns (n = 1, N = 8),
# 1.7–1.9 µs at 46–62 (n = 2, N = 6, 8), 4.1 µs at 127 (n = 1, N = 32), all at 512–2048
# samples; 3–4.5 µs at 4096, 8.3 µs at 16384 (n = 1, N = 8).
SIMULATION_SECONDS = 0.15
# NOTE: CPU seconds of one simulation (:func:`simulate`) per coordinate: measured 0.06–0.09 s
# for n = 1 and 2 (degrees 2–7, velocity terms), the compiled RK4 of 556 × 256 steps.
CROSSINGS_ESTIMATED = 4
# NOTE: the crossings an estimate allows for, each refined by up to REFINE_STEPS correctors
# and monodromies (their number is known only once the multipliers are).


def floquet_samples(omega: np.ndarray | float, top_frequency: float) -> np.ndarray:
    """The samples a period :func:`orbit_multipliers` takes at ``omega``:
    :data:`FLOQUET_SAMPLES` times the power of two above ``top_frequency/ω``."""
    ratio = np.maximum(1.0, top_frequency / np.asarray(omega, dtype=float))
    return FLOQUET_SAMPLES * 2 ** np.ceil(np.log2(ratio))


def dynamics_seconds(points: float, unknowns: int, coordinates: int, lo: float, hi: float,
                     top_frequency: float, point_seconds: float) -> float:
    """CPU seconds the stability and :func:`dynamics` of a traced curve of ``points`` points
    add, estimated before it is traced: every point's multipliers at the mean samples over
    ``[lo, hi]`` (:data:`FLOQUET_SAMPLE_SECONDS`), :data:`CROSSINGS_ESTIMATED` refinements
    of :data:`REFINE_STEPS` steps (a corrector of ``point_seconds`` and a monodromy each) and
    :data:`MAX_RUNS` simulations (:data:`SIMULATION_SECONDS` a coordinate).

    >>> round(dynamics_seconds(0, 31, 1, 1.0, 2.0, 1.0, 0.0), 2)  # 0.9 s of the simulations
    1.04
    """
    fixed, per_unknown, cached, growth = FLOQUET_SAMPLE_SECONDS
    samples = floquet_samples(np.linspace(lo, hi, 65), top_frequency)
    per_point = float(np.mean(samples * np.maximum(1.0, samples / cached) ** growth)) * (
        fixed + per_unknown * unknowns)
    return (points * per_point + CROSSINGS_ESTIMATED * REFINE_STEPS * (per_point + point_seconds)
            + MAX_RUNS * SIMULATION_SECONDS * coordinates)


@dataclass(frozen=True)
class Bifurcation:
    """A point of a traced branch where a Floquet multiplier crosses the unit circle: a fold
    (real, +1), a period doubling (real, −1) or a Neimark–Sacker point (a complex pair
    ``e^{±iθ}``), refined on the branch; the multipliers there, and which side is stable."""

    kind: str  # fold | period_doubling | neimark_sacker
    omega: float
    amplitudes: tuple[float, ...]  # each coordinate's first harmonic
    multipliers: tuple[complex, ...]  # by modulus
    piece: int
    before: int  # the curve's point before it
    residual: float  # |μ| − 1 of the crossing multiplier at the refined point
    stable_side: str  # lower | higher ω | none (unstable on both sides) | both


@dataclass(frozen=True)
class Attractor:
    """What RK4 from a slightly pushed unstable orbit at ``omega`` settles on after
    :data:`TRANSIENT_PERIODS`, over :data:`RECORD_PERIODS`: its kind (``period-k``,
    ``quasi-periodic``, ``chaotic``, ``growing``, ``unresolved``, ``escaped``), each
    coordinate's main spectral lines (ω-units, amplitude) and range; the second frequency of
    a torus."""

    omega: float
    interval: tuple[float, float]
    why: str
    kind: str
    period: int | None  # drive periods of a period-k attractor
    second_frequency: float | None  # ν, reduced to (0, ω/2]
    lines: tuple[tuple[tuple[float, float], ...], ...]  # per coordinate: (frequency, amplitude)
    ranges: tuple[tuple[float, float], ...]  # per coordinate: min, max over the record
    power_in_lines: float  # the share of the power on the lines m ω + n ν
    start_amplitudes: tuple[float, ...]  # the unstable orbit's first harmonics
    transient: int = TRANSIENT_PERIODS
    periods: int = RECORD_PERIODS


@dataclass(frozen=True)
class Dynamics:
    """The bifurcations of every branch and the attractors simulated, with the period-1 search's
    scope in words (``note``)."""

    bifurcations: tuple[Bifurcation, ...]
    attractors: tuple[Attractor, ...]
    unstable_intervals: tuple[tuple[float, float], ...]  # ω where no period-1 orbit is stable
    note: str

    @property
    def non_periodic(self) -> tuple[Attractor, ...]:
        """The attractors that are not period-1 orbits."""
        return tuple(a for a in self.attractors if a.kind not in ("period-1",))


def orbit_multipliers(fine: PolynomialBalance, X: np.ndarray, omega: np.ndarray,
                      top_frequency: float) -> np.ndarray:
    """Every Floquet multiplier of each balance solution ``X[k]`` at ``omega[k]``: the
    monodromy of its variational equation (:func:`numerics.floquet.variational_multipliers`),
    :data:`FLOQUET_SAMPLES` a period times the power of two above ``top_frequency/ω``;
    ``(points, 2n)``, by modulus."""
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    X = np.atleast_2d(X)
    out = np.empty((len(omega), 2 * fine.coordinates), dtype=complex)
    samples = floquet_samples(omega, top_frequency)
    for s in np.unique(samples):
        where_s = np.nonzero(samples == s)[0]
        # (chunks of ~2**15 samples in all; never an empty one: one point of 65536 samples)
        for chunk in np.array_split(where_s, min(len(where_s),
                                                 max(1, len(where_s) * int(s) // 2**15))):
            lin = [fine.linearization(X[i], omega[i], int(s)) for i in chunk]
            out[chunk] = variational_multipliers(np.array([a for a, _ in lin]),
                                                 np.array([b for _, b in lin]), omega[chunk])
    order = np.argsort(np.abs(out), axis=1, kind="stable")
    return np.take_along_axis(out, order, axis=1)


def _outside(lam: np.ndarray) -> tuple[int, int, int]:
    """How many multipliers lie outside the unit circle: complex pairs, real negative, real
    positive."""
    out = np.abs(lam) > NEUTRAL
    pair = np.abs(lam.imag) > COMPLEX * np.abs(lam)
    return (int(np.sum(out & pair)) // 2, int(np.sum(out & ~pair & (lam.real < 0))),
            int(np.sum(out & ~pair & (lam.real > 0))))


def _crossing(lam: np.ndarray, kind: str) -> float:
    """``|μ| − 1`` of the multiplier of ``kind`` nearest the unit circle (NaN: none): a
    complex pair's (Neimark–Sacker), a real negative one's (a period doubling; a pair with a
    negative real part where there is none yet)."""
    pair = np.abs(lam.imag) > COMPLEX * np.abs(lam)
    pick = pair if kind == "neimark_sacker" else ~pair & (lam.real < 0)
    if kind == "period_doubling" and not np.any(pick):
        # the pair that meets on the negative real axis within the step, before one leaves
        pick = pair & (lam.real < 0)
    if not np.any(pick):
        return math.nan
    d = np.abs(lam[pick]) - 1
    return float(d[np.argmin(np.abs(d))])


def _refine(fine: PolynomialBalance, y0: np.ndarray, y1: np.ndarray, g0: float, g1: float,
            kind: str, top: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The point between the curve's points ``y0``, ``y1`` where the crossing multiplier of
    ``kind`` has ``|μ| = 1``: Illinois' secant on the chord's fraction, each iterate corrected
    onto the curve (:func:`continuation._corrector` across the chord;
    :func:`numerics.newton.secant`, bracketed); ``(y, μ, |μ| − 1)``."""
    chord = y1 - y0
    t = chord / np.linalg.norm(chord)
    best = (y0, orbit_multipliers(fine, y0[:-1], y0[-1:], top)[0], g0)

    def crossing(s: float) -> float:
        nonlocal best
        try:
            y = _corrector(fine, y0 + s * chord, t)
        except np.linalg.LinAlgError:
            return math.nan  # stops the secant
        lam = orbit_multipliers(fine, y[:-1], y[-1:], top)[0]
        g = _crossing(lam, kind)
        if math.isfinite(g) and abs(g) < abs(best[2]):
            best = (y, lam, g)
        return g

    secant(crossing, 0.0, 1.0, g0, g1, ftol=1e-11, max_iter=REFINE_STEPS, bracketed=True)
    return best


def bifurcations(fine: PolynomialBalance, cont: Continuation, lam: np.ndarray,
                 top: float) -> tuple[Bifurcation, ...]:
    """Every crossing of the unit circle along the traced curve ``cont`` (``lam``: every
    point's multipliers, :func:`orbit_multipliers`): a complex pair (Neimark–Sacker) or a real
    multiplier through −1 (a period doubling) between two points, refined by :func:`_refine`;
    and each fold of the curve (``dω/ds = 0``), polished (:func:`continuation.fold_point`),
    with its multipliers."""
    out = []
    counts = [_outside(m) for m in lam]
    for k, piece in enumerate(cont.piece_slices()):
        for i in range(piece.start, piece.stop - 1):
            a, b = counts[i], counts[i + 1]
            y0 = np.append(cont.x[i], cont.omega[i])
            y1 = np.append(cont.x[i + 1], cont.omega[i + 1])
            kinds = []
            # (a pair that turns real within the step, or meets the other way, is no crossing)
            if b[0] != a[0] and b[1:] == a[1:]:
                kinds.append("neimark_sacker")
            if b[1] != a[1] and b[0] == a[0] and b[2] == a[2]:
                kinds.append("period_doubling")
            for kind in kinds:
                g0, g1 = _crossing(lam[i], kind), _crossing(lam[i + 1], kind)
                if not (math.isfinite(g0) and math.isfinite(g1)) or (g0 > 0) == (g1 > 0):
                    continue
                y, mu, g = _refine(fine, y0, y1, g0, g1, kind, top)
                out.append(_record(fine, kind, y, mu, g, k, i, a, b, cont))
            # a fold: the curve's ω turns between i and i + 1 (a real multiplier through +1)
            if i > piece.start and (cont.omega[i] - cont.omega[i - 1]) \
                    * (cont.omega[i + 1] - cont.omega[i]) < 0:
                y_prev = np.append(cont.x[i - 1], cont.omega[i - 1])
                try:
                    with np.errstate(over="ignore", invalid="ignore"):
                        z = fold_point(fine, y_prev, _tangent(fine, y_prev, y0 - y_prev),
                                       float(np.linalg.norm(y0 - y_prev)))
                    ok = bool(np.all(np.isfinite(z)))
                except np.linalg.LinAlgError:
                    ok = False
                if not ok:
                    z = y0
                mu = orbit_multipliers(fine, z[:-1], z[-1:], top)[0]
                real = mu[np.abs(mu.imag) <= COMPLEX * np.abs(mu)].real
                g = float(np.min(np.abs(real - 1))) if len(real) else math.nan
                out.append(_record(fine, "fold", z, mu, g, k, i, counts[i - 1], b, cont))
    return tuple(sorted(out, key=lambda e: (e.omega, e.piece)))


def _record(fine: PolynomialBalance, kind: str, y: np.ndarray, mu: np.ndarray, g: float,
            piece: int, i: int, a: tuple[int, int, int], b: tuple[int, int, int],
            cont: Continuation) -> Bifurcation:
    stable_a, stable_b = sum(a) == 0, sum(b) == 0  # the points on either side
    rising = cont.omega[i + 1] > cont.omega[i]
    side = ("both" if stable_a and stable_b else "none" if not (stable_a or stable_b)
            else ("higher" if stable_b == rising else "lower"))
    if kind == "fold":
        side = "lower" if stable_a and not stable_b else "higher" if stable_b else side
        # (a fold's two sides are both at lower or both at higher ω: which stretch is stable)
        side = {"lower": "before", "higher": "after"}.get(side, side)
    return Bifurcation(kind, float(y[-1]), tuple(float(r) for r in fine.first_harmonics(y[:-1])),
                       tuple(complex(m) for m in mu), piece, i, float(g), side)


def unstable_intervals(cont: Continuation, stable: np.ndarray, lo: float, hi: float
                       ) -> tuple[tuple[float, float], ...]:
    """The ω in ``[lo, hi]`` where no traced point is stable: the complement of every stable
    run's ω span, each run widened halfway to its unstable neighbours on the curve."""
    spans = []
    for piece in cont.piece_slices():
        w, s = cont.omega[piece], stable[piece]
        for j in range(len(w) - 1):
            if s[j] or s[j + 1]:
                mid = 0.5 * (w[j] + w[j + 1])
                a = w[j] if s[j] else mid
                b = w[j + 1] if s[j + 1] else mid
                spans.append((min(a, b), max(a, b)))
        if len(w) == 1 and s[0]:
            spans.append((w[0], w[0]))
    spans.sort()
    gaps, reach = [], lo
    for a, b in spans:
        if a > reach:
            gaps.append((reach, min(a, hi)))
        reach = max(reach, b)
    if reach < hi:
        gaps.append((reach, hi))
    return tuple((a, b) for a, b in gaps if b > a)


def _lines(y: np.ndarray, omega: float, periods: int) -> tuple[list, np.ndarray, np.ndarray]:
    """The Hann-windowed spectrum of one coordinate's record: its lines (frequency in ω's
    units, amplitude), the frequencies of the bins and their power."""
    n = len(y)
    w = np.hanning(n)
    spec = np.abs(np.fft.rfft((y - np.mean(y)) * w)) * 2 / np.sum(w)
    freq = np.arange(len(spec)) * omega / periods
    spec[0] = abs(np.mean(y))
    top = float(np.max(spec)) or 1.0
    peaks = [i for i in range(1, len(spec) - 1)
             if spec[i] >= spec[i - 1] and spec[i] > spec[i + 1] and spec[i] > LINE_FLOOR * top]
    lines = []
    for i in sorted(peaks, key=lambda i: -spec[i])[:LINES]:
        la, lb, lc = np.log(spec[i - 1:i + 2] + 1e-300)
        den = la - 2 * lb + lc
        d = 0.5 * (la - lc) / den if den != 0 else 0.0
        lines.append((float((i + d) * omega / periods), float(spec[i])))
    if spec[0] > LINE_FLOOR * top:
        lines.append((0.0, float(spec[0])))
    lines.sort(key=lambda e: -e[1])
    return lines[:LINES], freq, spec**2


def classify(record: np.ndarray, omega: float, samples: int, periods: int, n: int
             ) -> tuple[str, int | None, float | None, tuple, tuple, float]:
    """The kind of the attractor a record of :func:`numerics.integrate.record_system` shows:
    ``period-k`` where its stroboscopic points repeat after ``k`` periods
    (:data:`PERIOD_TOLERANCE`); else ``quasi-periodic`` where :data:`QUASI_POWER` of its
    spectrum lies on the lines ``m ω + n ν`` (:data:`COMBINATIONS`), ν the largest line off
    the harmonics of ω, and ``chaotic`` where it does not; ``growing`` where the amplitude
    still climbs through the record (:data:`GROWTH`: no bounded steady state);
    ``unresolved`` where the motion outruns RK4's step (:data:`RESOLVED_STEP`): no verdict.
    ``(kind, k, ν, lines, ranges, power on the lines)``."""
    x = record[:n]
    ranges = tuple((float(np.min(c)), float(np.max(c))) for c in x)
    scale = max(b - a for a, b in ranges) or 1.0
    step = 2 * np.pi / omega / (samples * RECORD_SUBSTEPS)
    rate = max(float(np.max(np.abs(v)) / max(np.max(np.abs(c)), 1e-300))
               for c, v in zip(x, record[n:2 * n], strict=True))
    if rate * step > RESOLVED_STEP:
        return "unresolved", None, None, (), ranges, 0.0
    strobe = record[:, ::samples]
    for k in range(1, MAX_PERIOD + 1):
        if np.max(np.abs(strobe[:, k:] - strobe[:, :-k])) < PERIOD_TOLERANCE * scale:
            break
    else:
        k = None
    body = x[:, :-1]  # whole periods only
    spectra = [_lines(c, omega, periods) for c in body]
    lines = tuple(tuple(s[0]) for s in spectra)
    bin_w = omega / periods
    if k is not None:
        return f"period-{k}", k, None, lines, ranges, 1.0
    spans = [float(np.max(np.ptp(q, axis=1))) for q in np.array_split(body, 4, axis=1)]
    if all(a < b for a, b in itertools.pairwise(spans)) and spans[-1] > GROWTH * spans[0]:
        return "growing", None, None, lines, ranges, 0.0
    # ν: the largest line of the largest coordinate not within two bins of a harmonic of ω
    main = int(np.argmax([b - a for a, b in ranges]))
    off = [f for f, _ in spectra[main][0]
           if f > 0 and abs(f / omega - round(f / omega)) * omega > 2 * bin_w]
    if not off:
        return "chaotic", None, None, lines, ranges, 0.0
    nu = off[0] % omega
    nu = min(nu, omega - nu)
    freq = spectra[main][1]
    on = np.zeros(len(freq), dtype=bool)
    for m in range(COMBINATIONS[0] + 1):
        for j in range(-COMBINATIONS[1], COMBINATIONS[1] + 1):
            on |= np.abs(freq - abs(m * omega + j * nu)) <= 2.01 * bin_w
    power = spectra[main][2]
    share = float(np.sum(power[on]) / np.sum(power)) if np.sum(power) > 0 else 0.0
    kind = "quasi-periodic" if share >= QUASI_POWER else "chaotic"
    return kind, None, float(nu), lines, ranges, share


def simulate(fine: PolynomialBalance, field: PolynomialField, drive: np.ndarray,
             omega: float, x: np.ndarray, interval: tuple[float, float], why: str
             ) -> Attractor:
    """The :class:`Attractor` DOP853 reaches from the balance orbit ``x`` at ``omega`` (an
    unstable one) pushed by :data:`PUSH`."""
    n = fine.coordinates
    y0 = fine.state(x, omega)
    y0 = y0 + PUSH * (1 + np.max(np.abs(y0))) * np.ones_like(y0)
    record = record_system(field, drive, omega, y0, TRANSIENT_PERIODS, RECORD_PERIODS,
                           RECORD_SAMPLES, RECORD_SUBSTEPS)
    start = tuple(float(r) for r in fine.first_harmonics(x))
    if record is None:
        return Attractor(omega, interval, why, "escaped", None, None, (), (), 0.0, start)
    kind, k, nu, lines, ranges, share = classify(record, omega, RECORD_SAMPLES,
                                                 RECORD_PERIODS, n)
    return Attractor(omega, interval, why, kind, k, nu, lines, ranges, share, start)


def neimark_sacker_stretches(found: tuple[Bifurcation, ...], cont: Continuation,
                             stable: np.ndarray) -> list[tuple[float, float, str, int]]:
    """The unstable stretch each Neimark–Sacker point of ``found`` begins: along the curve away
    from its stable side while the points are unstable, up to the first fold (where the curve
    turns back in ω, its refined ω from ``found``: past it the ω of the stretch repeat on
    another orbit, and the middle of the span could fall outside where the torus is born);
    ``(ω from, ω to, why, the unstable point nearest the middle)``."""
    folds = {(e.piece, e.before): e.omega for e in found if e.kind == "fold"}
    out = []
    for e in found:
        if e.kind != "neimark_sacker" or e.stable_side in ("none", "both"):
            continue
        piece = cont.piece_slices()[e.piece]
        # the unstable run beside the point: along the curve away from the stable side
        step = 1 if (e.stable_side == "lower") == (cont.omega[e.before + 1]
                                                   > cont.omega[e.before]) else -1
        j = e.before + (1 if step == 1 else 0)
        run: list[int] = []
        end, sense = None, cont.omega[j] - e.omega
        while piece.start <= j < piece.stop and not stable[j]:
            if run and (cont.omega[j] - cont.omega[run[-1]]) * sense < 0:
                # a fold at run[-1] (the curve's ω turns there)
                end = folds.get((e.piece, run[-1]))
                break
            run.append(j)
            j += step
        if not run:
            continue
        w = [*cont.omega[run], e.omega] + ([] if end is None else [end])
        a, b = float(min(w)), float(max(w))
        out.append((a, b, f"Neimark–Sacker at w = {e.omega:.6g}", int(
            run[int(np.argmin(np.abs(cont.omega[run] - 0.5 * (a + b))))])))
    return out


def dynamics(fine: PolynomialBalance, field: PolynomialField, drive: np.ndarray,
             cont: Continuation, lam: np.ndarray, lo: float, hi: float, top: float
             ) -> Dynamics:
    """The :class:`Dynamics` of a traced response: its :func:`bifurcations`; then one
    simulation (:func:`simulate`) at the middle of each ω interval where no period-1 orbit is
    stable and of each unstable stretch a Neimark–Sacker point begins (up to its first fold:
    :func:`neimark_sacker_stretches`), from the unstable point there nearest that ω (at most
    :data:`MAX_RUNS`, by ω)."""
    found = bifurcations(fine, cont, lam, top)
    stable = np.all(np.abs(lam) < NEUTRAL, axis=1)
    gaps = unstable_intervals(cont, stable, lo, hi)
    # each end of a gap moved onto the refined crossing that bounds it (the points are a
    # continuation step apart; the crossing is refined to ~1e-10)
    spacing = float(np.max(np.abs(np.diff(cont.omega)), initial=0.0))
    ends = [e.omega for e in found if e.stable_side not in ("none", "both")]
    gaps = tuple(tuple(min(ends, key=lambda w, v=v: abs(w - v))
                       if ends and min(abs(w - v) for w in ends) <= spacing and lo < v < hi
                       else v for v in gap) for gap in gaps)
    jobs: list[tuple[float, float, str, int | None]] = [(a, b, "no stable period-1 orbit", None)
                                                        for a, b in gaps]
    for job in neimark_sacker_stretches(found, cont, stable):
        if not any(abs(job[0] - p) < 1e-9 and abs(job[1] - q) < 1e-9 for p, q, *_ in jobs):
            jobs.append(job)
    jobs.sort()
    attractors = []
    for a, b, why, point in jobs[:MAX_RUNS]:
        mid = 0.5 * (a + b)
        if point is None:
            unstable = np.nonzero(~stable)[0]
            if not len(unstable):
                continue
            point = int(unstable[np.argmin(np.abs(cont.omega[unstable] - mid))])
        w = float(cont.omega[point])
        attractors.append(simulate(fine, field, drive, w, cont.x[point], (a, b), why))
    skipped = len(jobs) - min(len(jobs), MAX_RUNS)
    odd = [x for x in attractors if x.kind != "period-1"]
    note = ("complete about period-1 orbits (those of the drive's period) only"
            + (f"; {len(odd)} other attractor{'s' * (len(odd) != 1)} found by simulation ("
               + ", ".join(f"{x.kind} at w = {x.omega:.4g}" for x in odd)
               + "): a steady state that is not a period-1 orbit, or none where it grows or "
               "outruns the simulation's step" if odd else "")
            + (f"; {skipped} interval{'s' * (skipped != 1)} not simulated (at most {MAX_RUNS})"
               if skipped else ""))
    return Dynamics(found, tuple(attractors), gaps, note)
