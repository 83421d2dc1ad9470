"""Every bound of the package, in one place, and the one integer-range check.

It imports nothing of the package (and nothing heavy): the command line reads these bounds
while it parses its arguments, before SymPy or numba is loaded."""

from __future__ import annotations

from .errors import InputError

# --- orders ---------------------------------------------------------------------------------

SERIES_MAX_ORDER = 100_000
# NOTE: a hard sanity bound on any L–P order only; the CLI asks for --allow-slow far below it
# (cost estimate).
GENERATE_MAX_ORDER = 130
# NOTE: the bound is the emitted module's compilation, no longer its printing: a polynomial is
# one node the printer writes itself (order 300 prints in 40 s), but numba compiles the
# order-130 duffing module on its first import in 65 s and had not finished the order-300 one
# after 10 minutes; generate stops at 130, whatever --allow-slow says.
PERIOD_SERIES_ORDER = 60
# NOTE: the order of the exact series every period method of `choose period` is built from:
# order 60 takes ~0.1 s and reaches 1e-16 wherever |x| ≤ 0.5.
SLOW_FLOW_MAX_ORDER = 6
# NOTE: the slow flow (averaging): order 6 of van der Pol takes about half a second, the driven
# Duffing's order 4 one; each order costs 2–4× the one before (docs/benchmarks.md, "The slow
# flow").
DRIVEN_MAX_ORDER = 6
# NOTE: the exact μ-expansion's rational functions grow fast: `generate driven` at order 6 takes
# about 3 minutes, at 7 it would take about 20.
MU_EXACT_MAX_ORDER = 12
# NOTE: the exact μ-expansion (undamped, damped) and the symbolic balance take 1..12.
SSM_MAX_ORDER = 41
# NOTE: a spectral submanifold in floating point: past order ~40 its terms are rounding (a
# Duffing oscillator's reach orders of magnitude below 1e-16 by then).
SSM_MAX_POINTS = 100_000
# NOTE: drive frequencies of `ssm`'s forced response: each a bordered solve and the roots of
# one polynomial; 500 take a fraction of a second, 10⁵ a minute of a small system.
MU_MAX_ORDER = 200
# NOTE: the numeric μ-expansion at one ω: far above where it stops converging.
HILL_MAX_INDEX = 100
# NOTE: m indexes the tongue δ = m²/4 of ẍ + (δ + ε cos t)x = 0; far above any use.

# --- harmonics, drives, subharmonics --------------------------------------------------------

MAX_HARMONICS = 100
# NOTE: one bound for every --harmonics.  The numerical balance (200 unknowns, dense 200×200
# Newton steps) and shooting's sampling take up to 100; the emitted modules stop earlier
# (balance 12, fourier 60) and say so; the response's continuation refuses what it estimates
# at over a minute.
FOURIER_MAX_HARMONICS = 60
# NOTE: the emitted Fourier (AGM) evaluator of cn: 60 terms of the nome series.
MAX_DRIVES = 4
# NOTE: four drives make at most 228 tones to second order with a cubic force, fitted in ~3 s;
# the count grows like (2k)^5 combinations before the equal frequencies merge.
SUBHARMONIC_MAX_N = 12
# NOTE: the 1/n orbit spans n drive periods; at n = 12 shooting integrates 12 periods with
# 4096 RK4 steps each and the balance carries harmonics up to 2n + 1 of ω.
MAGNITUDES = (1e-16, 1e16)
# NOTE: every nonzero |ε|, |f|, ω and finite Q lies in this window.  The closed-form cubic in
# u = r² raises (1 − ω²)/ε to the sixth power, shooting cubes amplitudes up to fQ: within
# 1e±16 every such combination stays inside double precision (1e±288), beyond it some overflow.
# (Only εf² matters for the shape: q → λq maps ε, f to ελ², f/λ — rescale rather than widen.)
PARAMETRIC_MAX_POINTS = 401
# NOTE: ω points of `parametric`'s range: 401 draw a smooth curve; their cost with --harmonics
# is costs.parametric_cost's.

MAX_DRIVE_POINTS = 4000
# NOTE: points of a continuation in the drive amplitude from rest (the seeds of every orbit at
# one ω): it stops there and says its seeds may be incomplete.  ~12 s at 31 unknowns, ~23 s at
# 62 (a 2-DOF system at N = 8); a curve up to an amplitude bound of a few hundred takes 150–550
# points, one winding through the superharmonic resonances of a hardening system at half its
# lowest ω0 3300.  Points, not seconds: the seeds do not depend on how busy the machine is.
DRIVE_POINT_SECONDS = 3e-3
# NOTE: one point of that continuation at the coarse balance (at most 31 unknowns for one
# coordinate: an SVD and ~1.5 corrector solves), measured 2–3 ms: 4000 points in 12 s at most.

EXCHANGE_MAX_STEPS = 20_000
# NOTE: DOP853 steps of a resonant slow flow's energy exchange (rescaled to unit amplitude, so
# the count does not grow with it): two exchanges take 10–300 steps on the documented systems,
# ~0.3 ms each; a start that finds no two maxima in 20 000 (about 6 s) reports NaN.
WEAK_NONLINEARITY = 0.1
# NOTE: the first-order slow flow of a system's resonant modes averages a weak nonlinear force
# over the linear modes' fast oscillation; its error grows like the ratio of the nonlinear
# force at the start's peak coordinates to the slowest mode's linear restoring force ω0²·a
# (1.5 % at 0.3 for the swing spring, tests/test_resonance.py; for x1'' + x1 + 0.3 x1² x2 +
# 0.2 x1³, x2'' + 9 x2 + …: 1 % at 0.05, 6 % at 0.2, and at 0.8 the printed exchange period
# was one fast period where the full equations exchange nothing). `slowflow SYSTEM --start`
# refuses above 0.1.

# --- work -------------------------------------------------------------------------------------

COST_LIMIT_SECONDS = 60.0
# NOTE: above this estimate the CLI asks for --allow-slow instead of running for minutes or hours.
SLOW_LIMIT_SECONDS = 7 * 24 * 3600.0
# NOTE: above this estimate (a week) a command is refused even with --allow-slow: an order of
# 29 digits was estimated at 6e90 s, and the switch would have let it run without end.
MAX_WORKERS = 64
# NOTE: a bound against typos (workers=1000 on a laptop), far above this machine's 2 cores.
SWEEP_MAX_VALUES = 100_000
# NOTE: values per sweep axis: a bound against typos in A:B:N; the store's size is checked
# against the free disk before any work.


def check_int(value: object, lo: int, hi: int | None = None, message: str | None = None
              ) -> int:
    """``value`` when it is an integer (``bool`` is not) in ``lo..hi`` (no upper bound for
    ``hi = None``); else :class:`InputError` with ``message`` (default: ``"{value!r}: must be
    an integer in lo..hi"``)."""
    import numbers

    ok = (not isinstance(value, bool) and isinstance(value, numbers.Integral)
          and lo <= value and (hi is None or value <= hi))
    if not ok:
        bound = f"an integer ≥ {lo}" if hi is None else f"an integer in {lo}..{hi}"
        raise InputError(message or f"{value!r}: must be {bound}")
    return int(value)
