"""Resummations verified before they are emitted: a limit cycle's Padé in ε and q(s),
Mathieu's a_m(q), b_m(q) and Hill's transition curves, each checked against its reference
on a grid out to where it holds."""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction

import numpy as np

from ..algebra.resum import (
    Resummed,
    nearest_singularity,
    resum_frequency,
    resum_harmonic,
    resum_relaxation,
    resum_series,
    series_radius,
    van_der_pol_relaxation,
)
from ..errors import InputError
from ..lower.records import (
    ResummedCurve,
    ResummedCycle,
    ResummedMathieu,
    ResummedTongue,
)
from ..numerics.references import cycle_reference, cycle_samples

RESUM_TOLERANCE = 1e-6
# NOTE: the relative error the resummed limit-cycle evaluators are verified to (the target
# for 1 < ε ≤ 10); within |ε| ≤ 1 they are far better (3e-14 from order 60 on).
RESUM_RANGE = 10.0
RESUM_GRID = 400
RESUM_SPREAD_MARGIN = 10.0
# NOTE: the neighbour spread [L/M] − [L−1/M−1] underestimates van der Pol's true error by up
# to 7× at large ε (order 130): the dense grid asks the spread for tolerance/10, and the
# shooting references then check it.
RELAXATION_SPREAD_MARGIN = 1.0
# NOTE: for the relaxation form (resum.resum_relaxation) the spread is 0.3× (order 130) to
# 10× (order 164) van der Pol's true error at ε = 10 (benchmarks/resum_relaxation.py): the
# grid asks it for the tolerance itself, and the shooting checks at every integer ε and at
# the end decide (the error grows monotonically with ε on the measured grid).
RESUM_CHECKS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0)
RELAXATION_TERMS = {
    frozenset({(0, 1, 1), (2, 1, -1)}): van_der_pol_relaxation,  # van der Pol
    frozenset({(0, 1, 1), (0, 3, Fraction(-1, 3))}): van_der_pol_relaxation,  # Rayleigh
}
# NOTE: the oscillators whose relaxation limit is known (Rayleigh's q̇ obeys van der Pol's
# equation, so the two share ω(ε)); keyed by the terms q^a q̇^b c of f(q, q̇).


def resum_cycle(lc: object, tolerance: float = RESUM_TOLERANCE) -> ResummedCycle | str:
    """The resummed ω(ε) of a limit cycle (:func:`resum.resum_relaxation` for the oscillators
    of :data:`RELAXATION_TERMS`, else :func:`resum.resum_frequency`) and its amplitude
    q(0) (Padé in ε², :func:`resum.resum_series`), each with the |ε| up to which it is
    verified: the neighbour spread below ``tolerance/margin`` on a dense grid of ``(0, 10]``, then
    DOP853 shooting (:func:`numerics.cycle_reference`) at the check points up to there and at
    its end, the domain cut at the last one passed when one fails.  Why not, where there is
    none: a series with odd powers of ε, no singularity estimate, a resummation that fails or
    that no check point verifies."""
    import numpy as np

    est = nearest_singularity(lc.omega)
    if est is None:
        return "ω's series gives no estimate of its nearest singularity"
    if not est.variable.endswith("**2"):
        return "ω's series has odd powers of ε (the resummation is in ε²)"
    if est.method != "Mercer–Roberts":
        return (f"ω's nearest singularity is estimated by {est.method}, not by Mercer and "
                "Roberts' ratios (a pair of complex singularities the Padé form is built on)")
    relaxation = RELAXATION_TERMS.get(frozenset(
        (a, b, Fraction(c)) for a, b, c in getattr(lc.model, "terms", ())))
    try:
        form = (resum_relaxation(lc.omega, est.radius, est.angle, relaxation())
                if relaxation else resum_frequency(lc.omega, est.radius, est.angle))
    except InputError as exc:
        return str(exc)
    refs: dict[float, object] = {}

    def reference(e: float) -> object:
        if e not in refs:
            refs[e] = cycle_reference(lc.model, e, guess=float(lc.amplitude[0]))
        return refs[e]

    omega = _verified(form, lambda e: 2 * np.pi / reference(e).period, tolerance,
                      RELAXATION_SPREAD_MARGIN if form.log is not None else RESUM_SPREAD_MARGIN)
    if omega is None:
        return (f"the resummed ω meets {tolerance:g} at no check point (its neighbour spread, "
                "or its error against shooting, is larger from the smallest ε on)")
    try:
        amplitude = resum_series(lc.amplitude, RESUM_RANGE)
    except InputError:
        amplitude = None
    amp = _verified(amplitude, lambda e: reference(e).q0, tolerance) if amplitude else None
    harmonics, q_verified = _resum_q(lc, form, tolerance, reference)
    return ResummedCycle(form, *omega, tolerance=tolerance,
                         amplitude=amplitude if amp else None,
                         amplitude_verified=amp if amp else (0.0, (), float("nan")),
                         harmonics=harmonics, harmonics_verified=q_verified)


HARMONIC_TAIL = 1e-3
# NOTE: q_resummed's harmonics are resummed in increasing n until two in a row stay below
# tolerance·HARMONIC_TAIL wherever the summed spread allows (van der Pol from order 100: ~40
# of its 201 cos/sin series); then the smallest are dropped while their largest values on the
# verified range add up to less than tolerance·HARMONIC_TAIL.
Q_SAMPLES = 64
# NOTE: q_resummed is checked against the shot cycle at this many times of one period.


def _resum_q(lc: object, form: Resummed, tolerance: float, reference: Callable
             ) -> tuple[tuple[tuple[str, int, Resummed], ...],
                        tuple[float, tuple[float, ...], float]]:
    """The Fourier coefficients of ``q(s)`` each resummed (:func:`resum.resum_harmonic`, in
    ω's ``w``) and the |ε| up to which their sum, at ``s = form(ε)·t``, is within
    ``tolerance`` of max |q| of the shot cycle over one period: the summed neighbour spread
    on the grid of :func:`resum_cycle`, then the shooting checks (nothing when ω's form has
    no ``w`` or no coefficient resums)."""
    none: tuple = ((), (0.0, (), float("nan")))
    if form.R is None:
        return none
    table: dict[tuple[str, int], list[Fraction]] = {}
    K = len(lc.q) - 1
    for j, (cos, sin) in enumerate(lc.q):
        for kind, part in (("cos", cos), ("sin", sin)):
            for n, c in part.items():
                table.setdefault((kind, n), [Fraction(0)] * (K + 1))[j] = Fraction(c)
    grid = np.linspace(0.0, RESUM_RANGE, RESUM_GRID + 1)[1:]
    spread = np.zeros_like(grid)
    forms: list[tuple[str, int, Resummed]] = []
    quiet = 0
    for n in sorted({n for _, n in table}):
        largest = 0.0
        for kind in ("cos", "sin"):
            if (kind, n) not in table:
                continue
            try:
                f = resum_harmonic(table[kind, n], form.R, form.p)
            except InputError:  # too few terms, or poles: left out, the checks decide
                continue
            forms.append((kind, n, f))
            spread = spread + np.nan_to_num(f.spread(grid), nan=np.inf)
            inside = grid[: _first_false(spread <= tolerance)]
            largest = max(largest, float(np.max(np.abs(f(inside)))) if inside.size else 0.0)
        quiet = quiet + 1 if largest <= tolerance * HARMONIC_TAIL else 0
        if quiet == 2:
            break
    end = _first_false(spread <= tolerance)
    if not forms or end == 0:
        return none
    inside = grid[:end]
    sizes = sorted(((float(np.max(np.abs(f(inside)))), i) for i, (_, _, f) in enumerate(forms)))
    dropped, total = set(), 0.0
    for size, i in sizes:
        if total + size > tolerance * HARMONIC_TAIL:
            break
        dropped.add(i)
        total += size
    forms = [h for i, h in enumerate(forms) if i not in dropped]

    def q(t: np.ndarray, e: float) -> np.ndarray:
        s = float(form(e)) * t
        return sum(f(e) * (np.cos(n * s) if kind == "cos" else np.sin(n * s))
                   for kind, n, f in forms)

    def error(e: float) -> float:
        t, truth = cycle_samples(lc.model, e, reference(e), Q_SAMPLES)
        return float(np.max(np.abs(q(t, e) - truth)) / np.max(np.abs(truth)))

    checked = _checked(round(float(inside[-1]), 12), error, tolerance)
    return (tuple(forms), checked) if checked else none


def _first_false(ok: np.ndarray) -> int:
    """The index of the first False in ``ok`` (its length when there is none)."""
    return int(np.argmin(ok)) if not ok.all() else len(ok)


def _checked(limit: float, error: Callable[[float], float], tolerance: float
             ) -> tuple[float, tuple[float, ...], float] | None:
    """``(limit, points, worst)``: ``error`` at the check points below ``limit`` and at
    ``limit`` itself, the domain cut at the last point passed when one misses ``tolerance``;
    None when the first misses."""
    points, worst = [], 0.0
    for e in [e for e in RESUM_CHECKS if e < limit] + [limit]:  # and the end itself
        err = error(e)
        if not err <= tolerance:
            limit = points[-1] if points else 0.0
            break
        points.append(e)
        worst = max(worst, err)
    return (float(limit), tuple(points), worst) if points else None


def _verified(form: Resummed, truth: Callable[[float], float], tolerance: float,
              margin: float = RESUM_SPREAD_MARGIN
              ) -> tuple[float, tuple[float, ...], float] | None:
    """``(limit, points, worst)`` of :func:`resum_cycle`'s rule, None if not even its first
    check point passes."""
    import numpy as np

    grid = np.linspace(0.0, RESUM_RANGE, RESUM_GRID + 1)[1:]
    end = _first_false(form.spread(grid) <= tolerance / margin)
    if end == 0:
        return None

    def error(e: float) -> float:
        value = truth(e)
        return abs(float(form(e)) - value) / abs(value)

    return _checked(round(float(grid[end - 1]), 12), error, tolerance)


MATHIEU_TOLERANCE = 1e-15
# NOTE: relative to max(1, |a|), about four units in the last place: the Padé value is the
# start of a Newton step on the determinant of the recurrence (numerics.mathieu_newton),
# verified against numerics.mathieu_refined (30 digits); SciPy's mathieu_a, mathieu_b are
# 2e-16 … 0.7 off (benchmarks/resum.py).
MATHIEU_START_TOLERANCE = 1e-9
# NOTE: the Padé value must be this close for one Newton step: the step squares the relative
# error (times |a| over the gap to the neighbouring eigenvalue, ≥ 1 here), so 1e-9 → ~1e-18.
MATHIEU_TRUNCATION = 1e-17
# NOTE: relative to max(1, |a|): the truncated recurrence's eigenvalue is within this of the
# infinite one (numerics.mathieu_truncation_bound), well below the rounding of a float64.
MATHIEU_NEWTON_STEPS = 1
MATHIEU_RANGE = 50.0
MATHIEU_GRID = 400
# NOTE: q ∈ (0, 50] on 400 points: beyond q ≈ 50 no Padé of an order-100 series is within
# 1e-9 (a_m(q) ~ −2q + 2(2m + 1)√q, a branch at infinity); the eigenvalue solver is the
# method there.


def mathieu_rows(kind: str, m: int, q: float, a: float) -> int:
    """The fewest rows of the recurrence whose eigenvalue is within ``MATHIEU_TRUNCATION``
    ·max(1, |a|) of the infinite one at ``q`` (:func:`numerics.mathieu_truncation_bound`)."""
    from ..numerics.references import mathieu_recurrence, mathieu_truncation_bound

    rows = mathieu_recurrence(kind, m, 1)[0] + 2
    while mathieu_truncation_bound(kind, m, q, a, rows) > MATHIEU_TRUNCATION * max(1.0, abs(a)):
        rows += 1
    return rows


MATHIEU_STARTS = (1.0, 0.75, 0.5, 0.4, 0.3, 0.2)
# NOTE: the Padé start is a measured choice, not the user's order: the near-diagonal Padé of
# the exact series truncated at ⌊f·order⌋ for each fraction f here is verified (Padé start
# within MATHIEU_START_TOLERANCE, refined value within the tolerance, the same grid and rule);
# the start kept is the one of fewest Padé degrees L + M whose limit is within one grid step
# of the longest found (a tie → the higher order).  The ufunc's time is the start's Horner
# pair and the Newton step's rows: for a_1 at order 100 the truncation at 50 ([21/29] in q)
# holds to q = 4.75 at 27 ns per point, the [50/50] of the whole series only to 2.625 at 93 ns
# (benchmarks/resum.py).


def _mathieu_verified(kind: str, m: int, form: Resummed, grid, ref, scale, tolerance: float
                      ) -> tuple[int, int, float]:
    """How many grid points from the first one ``form`` then the Newton step hold (the Padé
    start within ``MATHIEU_START_TOLERANCE``, the refined value within ``tolerance``), with
    the rows used and the largest error there (0 points: no rows, NaN)."""
    import numpy as np

    from ..numerics.references import mathieu_newton

    start = form(grid)
    ok = np.abs(start - ref) / scale <= MATHIEU_START_TOLERANCE
    n = int(np.argmin(ok)) if not ok.all() else len(grid)
    if n == 0:
        return 0, 0, float("nan")
    rows = 1 + max(mathieu_rows(kind, m, float(q), float(a)) for q, a in zip(grid[:n], ref[:n],
                                                                             strict=True))
    value = mathieu_newton(kind, m, grid[:n], start[:n], rows, MATHIEU_NEWTON_STEPS)
    error = np.abs(value - ref[:n]) / scale[:n]
    ok = error <= tolerance
    n = int(np.argmin(ok)) if not ok.all() else n
    return n, rows, float(error[:n].max()) if n else float("nan")


def resum_mathieu(kind: str, m: int, order: int, tolerance: float = MATHIEU_TOLERANCE
                  ) -> ResummedMathieu:
    """Padé of Mathieu's exact series (:func:`hill.mathieu_series`, in q², or in q when it
    has odd powers), then one Newton step on the determinant of the recurrence truncated to
    the rows :func:`mathieu_rows` asks for on the whole range (one row more, for between the
    grid points), verified on a dense grid of ``(0, 50]`` against
    :func:`numerics.mathieu_refined`: ``limit`` is the last grid point before the first
    where the Padé start misses ``MATHIEU_START_TOLERANCE`` or the refined value misses
    ``tolerance``.  The start is the series truncated at one of ``MATHIEU_STARTS`` × ``order``
    (the rule in its NOTE)."""
    import numpy as np

    from ..derive.hill import mathieu_series
    from ..numerics.references import mathieu_refined

    series = mathieu_series(kind, m, order)
    grid = np.linspace(0.0, MATHIEU_RANGE, MATHIEU_GRID + 1)[1:]
    ref = np.array([float(mathieu_refined(kind, m, float(q))) for q in grid])
    scale = np.maximum(1.0, np.abs(ref))
    found = []
    for k in sorted({int(f * order) for f in MATHIEU_STARTS}, reverse=True):
        try:
            form = resum_series(series[: k + 1], MATHIEU_RANGE)
        except InputError:
            continue
        n, rows, checked = _mathieu_verified(kind, m, form, grid, ref, scale, tolerance)
        if n:
            found.append((sum(form.approximant.degrees), -k, n, rows, checked, form))
    if not found:
        raise InputError(f"{kind}_{m}, order {order}: no resummed start is within "
                         f"{MATHIEU_START_TOLERANCE:g}, refined to {tolerance:g}, already at "
                         f"q = {grid[0]:g}; raise --order")
    longest = max(c[2] for c in found)
    _, _, n, rows, checked, form = min(c for c in found if c[2] >= longest - 1)
    return ResummedMathieu(kind, m, order, form, float(grid[n - 1]), tolerance, checked, rows,
                           MATHIEU_NEWTON_STEPS)


TONGUE_TOLERANCE = 1e-10
# NOTE: absolute, in δ.  The boundary is brentq on |tr M| − 2 with the compiled RK4 monodromy
# at TONGUE_STEPS and twice as many; a grid point counts only where the two agree to
# TONGUE_TOLERANCE / 10 (measured for p = cos t + cos 2t/2, n = 1: ≤ 5e-13 up to ε = 3).
TONGUE_STEPS = 4096
TONGUE_RADII = 3.0
TONGUE_RANGE = 10.0
TONGUE_GRID = 240
# NOTE: each curve is verified on 240 points of (0, ε_max], ε_max = 3 × its estimated radius
# (algebra.resum.series_radius; TONGUE_RANGE without an estimate), capped at 10: past a few
# radii no near-diagonal Padé of an order-30 series holds 1e-10.  At each point |tr M| − 2
# must change sign between δ ∓ b (b = the tolerance, or half the distance to another curve if
# less: the curves of tongue n split at ε^n only), which puts a boundary within the
# tolerance; the root by linear interpolation there (|tr M| is smooth on 2b ≤ 2e-10) is the
# measured error.  Four monodromies a point in four vectorised calls, no root search: 240
# points cost what 24 brentq searches did.


def boundary_bracket(p: dict[int, tuple[float, float]], eps: np.ndarray, near: np.ndarray,
                     bracket: np.ndarray, steps: int) -> np.ndarray:
    """The δ in ``near ± bracket`` where ``|tr M| = 2`` at each ``eps`` (the sign change of
    ``|tr M| − 2`` between the two ends of :func:`numerics.floquet_traces`, the root by linear
    interpolation), NaN where the sign does not change (no boundary or two in the bracket)."""
    from ..numerics.floquet import floquet_traces

    below, above = (np.abs(floquet_traces(near + s * bracket, eps, p, steps=steps)[0]) - 2
                    for s in (-1, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        root = near - bracket + 2 * bracket * below / (below - above)
    return np.where(below * above < 0, root, np.nan)


def resum_tongue(text: str, n: int, order: int, tolerance: float = TONGUE_TOLERANCE
                 ) -> ResummedTongue:
    """Each transition curve of tongue ``n`` of ``ẍ + (δ + ε p(t))x = 0`` (``p`` as text) as
    the Padé of its exact series (:func:`hill.transition_curves`, :func:`resum.resum_series`),
    verified against the Floquet boundary (:func:`boundary_bracket` at ``TONGUE_STEPS`` and
    twice as many, agreeing to ``tolerance / 10``) on ``TONGUE_GRID`` points of
    ``(0, ε_max]``: ``limit`` is the last grid point before the first miss.
    :class:`InputError` if a curve misses at the first point."""
    import numpy as np

    from ..derive.hill import fourier_of_text, transition_curves

    harmonics = fourier_of_text(text)
    p = {k: (float(a), float(b)) for k, (a, b) in harmonics.items()}
    series = transition_curves(harmonics, n, order).curves
    tops, forms = [], []
    for curve in series:
        radius = series_radius(curve.delta)  # inf when too short for an estimate
        tops.append(min(TONGUE_RADII * radius, TONGUE_RANGE))
        forms.append(resum_series(list(curve.delta), tops[-1]))
    curves = []
    for i, (curve, top, form) in enumerate(zip(series, tops, forms, strict=True)):
        grid = np.linspace(0.0, top, TONGUE_GRID + 1)[1:]
        values = form(grid)
        bracket = np.full(grid.size, tolerance)
        for j, other in enumerate(forms):
            if j != i:
                bracket = np.minimum(bracket, np.abs(other(grid) - values) / 2)
        usable = np.isfinite(values) & (bracket > 0)  # NaN in floquet_traces is an InputError
        near, bracket = np.where(usable, values, 0.0), np.where(usable, bracket, tolerance)
        ref, finer = (boundary_bracket(p, grid, near, bracket, steps)
                      for steps in (TONGUE_STEPS, 2 * TONGUE_STEPS))
        error = np.abs(values - finer)
        held = usable & (np.abs(ref - finer) <= tolerance / 10) & (error <= tolerance)
        count = grid.size if held.all() else int(np.argmin(held))
        if count == 0:
            raise InputError(f"tongue {n} of p(t) = {text!r}, curve {curve.label}: the "
                             f"resummed series misses the Floquet boundary by more than "
                             f"{tolerance:g} already at eps = {grid[0]:g}; raise --order (or "
                             "the curves coincide: a closed tongue)")
        curves.append(ResummedCurve(curve.label, form, round(float(grid[count - 1]), 12),
                                    float(error[:count].max())))
    return ResummedTongue(text, n, order, tolerance, tuple(curves))
