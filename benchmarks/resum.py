"""Past the radius of convergence: van der Pol's ω(ε) and Mathieu's a_m(q), b_m(q) resummed.

    .venv/bin/python benchmarks/resum.py

1. The forms tried for van der Pol's ω, from the exact series to order 130 (ω in ε², 66
   terms), against DOP853 shooting (numerics.cycle_reference, rtol 1e-13) at ε = 1, 3, 5, 10;
   the amplitude q(0) as Padé in ε² from orders 60, 100, 130, 164.
2. Error against cost on ε ∈ [0.1, 1], [0.1, 5], [0.1, 10]: the partial sums (NaN beyond 90 %
   of the estimated radius, as emitted), the resummed form emitted for van der Pol (the
   relaxation form, resum.resum_relaxation) from orders 60, 100, 130, 164 (NaN where the neighbour
   spread exceeds 1e-6, the generation rule before its shooting checks),
   shooting at three tolerances; ns per point measured in this run beside the recorded ones
   the chart uses (so that it is byte-identical on every run).
3. SciPy's mathieu_a, mathieu_b and the emitted evaluators (Padé + one Newton step, order 100)
   for every m ≤ 6 against the 30-digit reference (numerics.mathieu_refined) on q ∈ (0, 50];
   ns per point of each against SciPy in the same run, and of SymPy's lambdify of the series.

Writes docs/figures/resummed_speed_accuracy.png and docs/figures/mathieu_accuracy.png and
prints the tables; with --mathieu-only, part 3 and docs/figures/mathieu_accuracy.png alone:

    .venv/bin/python benchmarks/resum.py --mathieu-only
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp
from lindstedt.algebra.resum import (
    compose,
    diagonal_pade,
    horner_float,
    in_power,
    resum_frequency,
    resum_relaxation,
    resum_series,
    van_der_pol_relaxation,
    w_of,
    w_substitution,
)
from lindstedt.charts import mathieu_accuracy_figure, resummed_speed_accuracy_figure
from lindstedt.compiler import generate_limit_cycle, generate_mathieu
from lindstedt.derive.cycles import derive_limit_cycle
from lindstedt.derive.hill import mathieu_series
from lindstedt.derive.lindstedt import nearest_singularity
from lindstedt.derive.models import series_model
from lindstedt.emit.render import load_generated
from lindstedt.errors import InputError
from lindstedt.methods.verify import RELAXATION_SPREAD_MARGIN, RESUM_TOLERANCE
from lindstedt.numerics.references import cycle_reference, mathieu_reference, mathieu_refined
from scipy.special import mathieu_a, mathieu_b
from timing import best

ORDER = 164
FORMS_ORDER = 130
EPS = (0.1, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0, 9.0,
       10.0)
RANGES = (1.0, 5.0, 10.0)
SERIES_ORDERS = (10, 20, 40, 60, 100, 130)
RESUM_ORDERS = (60, 100, 130, 164)
SHOOT_RTOLS = (1e-7, 1e-10)
RECORDED_NS = {"series": 3.0, "resummed": 5.2, "lambdify": 60.0,
               "shooting 1e-07": 2.5e8, "shooting 1e-10": 6.0e8, "shooting 1e-13": 1.5e9}
# NOTE: ns per point recorded on the 2-core machine (docs/benchmarks.md, load ≈ 1–2): the
# emitted `_into` loops of omega (series) and omega_resummed (the relaxation form, order 58;
# 2026-12-02, with the cube root's scaled start) over 10⁶ points, lambdify of the
# order-60 partial sum, one DOP853 shooting per ε (two tolerances for the 1e-13 reference).
MATHIEU = (*(("a", m) for m in range(7)), *(("b", m) for m in range(1, 7)))
MATHIEU_DRAWN = (("a", 0), ("a", 6), ("b", 6))
FIGURE_DIR = Path(__file__).resolve().parent.parent / "docs" / "figures"
FIGURE = FIGURE_DIR / "resummed_speed_accuracy.png"
MATHIEU_FIGURE = FIGURE_DIR / "mathieu_accuracy.png"


def forms_table(omega: list, eps: np.ndarray, truth: np.ndarray) -> None:
    """Every form tried, its [L/M], real poles on the range, its error at ε = 1, 3, 5, 10."""
    _, c = in_power(omega)
    N = len(c) - 1
    est = nearest_singularity(omega)
    sq = [sum((c[i] * c[k - i] for i in range(k + 1)), 0) for k in range(N + 1)]
    tau = [1 / c[0]]
    for k in range(1, N + 1):
        tau.append(-sum((c[i] * tau[k - i] for i in range(1, k + 1)), 0) / c[0])
    tau2 = [sum((tau[i] * tau[k - i] for i in range(k + 1)), 0) for k in range(N + 1)]
    R = resum_frequency(omega, est.radius, est.angle)
    x = eps**2
    w = w_of(x, float(R.R), float(R.p))
    xs = w_substitution(R.R, R.p, N)
    rows = []
    for name, coeffs, var, back in (
            ("Padé of ω in ε²", c, x, lambda v: v),
            ("Padé of T/2π in ε²", tau, x, lambda v: 1 / v),
            ("Padé of (T/2π)² in ε²", tau2, x, lambda v: 1 / np.sqrt(v)),
            ("Padé of ω in w", compose(c, xs, N), w, lambda v: v),
            ("Padé of ω² in w", compose(sq, xs, N), w, lambda v: np.sqrt(v))):
        hi = 1.0 if var is w else 100.0
        try:
            P, _ = diagonal_pade(coeffs, 0.0, hi)
            rows.append((name, P.degrees, back(P(var))))
        except InputError as exc:  # no pole-free near-diagonal approximant
            rows.append((name, str(exc)[:30], np.full_like(eps, np.nan)))
    rows.append(("partial sum in w", (N, 0), horner_float(compose(c, xs, N), w)))
    rows.append(("√((1 − w)·Padé of ω²/(1 − w))", R.approximant.degrees, R(eps)))
    relax = resum_relaxation(omega, est.radius, est.angle, van_der_pol_relaxation())
    rows.append(("relaxation form, emitted", relax.approximant.degrees, relax(eps)))
    print(f"\nvan der Pol ω from order {FORMS_ORDER}: R = {est.radius:.6f}, β = {est.angle:.6f} "
          f"(rationals R = {R.R}, R cos β = {R.p}); relative error at ε =")
    cols = [i for i, e in enumerate(eps) if e in (1.0, 3.0, 5.0, 10.0)]
    print(f"{'form':<42}{'[L/M]':>10}" + "".join(f"{eps[i]:>10g}" for i in cols))
    for name, deg, val in rows:
        err = np.abs(val - truth) / truth
        print(f"{name:<42}{deg!s:>10}" + "".join(f"{err[i]:>10.1e}" for i in cols))


def amplitude_table(lc, eps: np.ndarray, refs: list) -> None:
    """q(0) as Padé in ε² (amplitude_resummed's form) against the shot cycles."""
    A = np.array([r.q0 for r in refs])
    print("\namplitude q(0), Padé in ε², relative error at ε =")
    print(f"{'order':<8}{'[L/M]':>10}" + "".join(f"{e:>9g}" for e in eps[::3]))
    for K in (60, 100, FORMS_ORDER, ORDER):
        r = resum_series(lc.amplitude[: K + 1], 10.0)
        err = np.abs(r(eps) - A) / A
        print(f"{K:<8}{r.approximant.degrees!s:>10}" + "".join(f"{e:>9.0e}" for e in err[::3]))


def cycle_panels(lc, eps: np.ndarray, truth: np.ndarray, shots: dict) -> list:
    """The chart's points per range: (method, label, recorded ns, max error on the range)."""
    est = nearest_singularity(lc.omega)
    guard = 0.9 * est.radius**0.5
    values = []
    for K in SERIES_ORDERS:
        v = horner_float(lc.omega[: K + 1], eps)
        values.append(("series", f"K={K}", RECORDED_NS["series"],
                       np.where(eps < guard, v, np.nan)))
    values.append(("lambdify", "K=60", RECORDED_NS["lambdify"],
                   horner_float(lc.omega[:61], eps)))
    for K in RESUM_ORDERS:  # the form generate emits for van der Pol: the relaxation form
        e = nearest_singularity(lc.omega[: K + 1])
        R = resum_relaxation(lc.omega[: K + 1], e.radius, e.angle, van_der_pol_relaxation())
        grid = np.linspace(0, 10, 401)[1:]
        bad = grid[~(R.spread(grid) <= RESUM_TOLERANCE / RELAXATION_SPREAD_MARGIN)]
        limit = bad[0] - grid[0] if bad.size else 10.0
        values.append(("resummed", f"K={K}", RECORDED_NS["resummed"],
                       np.where(eps <= limit, R(eps), np.nan)))
    for label, v in shots.items():
        values.append(("shooting", label, RECORDED_NS[f"shooting {label}"], v))
    panels = []
    for hi in RANGES:
        sel = eps <= hi
        points = []
        for method, label, ns, v in values:
            err = np.abs(v[sel] - truth[sel]) / truth[sel]
            points.append((method, label, ns, float(err.max()) if np.all(np.isfinite(err))
                           else np.inf))
        panels.append((f"ε ∈ [0.1, {hi:g}]", points))
    return panels


def cycle_timings(lc) -> None:
    """This run's ns per point: the emitted module (order 58), lambdify, shooting."""
    vdp = series_model("van_der_pol", 60)
    x = np.random.default_rng(0).uniform(0.1, 2.9, 1_000_000)
    out = np.empty_like(x)
    with tempfile.TemporaryDirectory() as folder:
        generate_limit_cycle(vdp, 58, Path(folder))
        mod = load_generated(Path(folder) / "van_der_pol.py")
        rows = []
        for name in ("omega", "omega_resummed", "period_resummed"):
            f, into = getattr(mod, name), getattr(mod, name + "_into")
            f(x[:10]), into(out, x)
            rows.append((name + " (ufunc)", best(lambda f=f: f(x), 5) / x.size * 1e9))
            rows.append((name + " (_into)", best(lambda i=into: i(out, x), 5) / x.size * 1e9))
    e = sp.Symbol("eps")
    poly = sum(sp.Rational(c.numerator, c.denominator) * e**j
               for j, c in enumerate(lc.omega[:61]))
    lam = sp.lambdify(e, poly, "numpy")
    rows.append(("lambdify, order 60", best(lambda: lam(x), 3) / x.size * 1e9))
    for rtol in (*SHOOT_RTOLS, 1e-13):
        t = best(lambda r=rtol: cycle_reference(vdp, 2.0, rtol=r), 1)
        rows.append((f"shooting rtol {rtol:g} (both tolerances)", t * 1e9))
    print("\nns per point, this run (1e6 points in [0.1, 2.9]):")
    for name, ns in rows:
        print(f"  {name:<42}{ns:>14.3g}")


def mathieu_part() -> tuple[np.ndarray, dict]:
    """Per m ≤ 6: SciPy's and the emitted (order 100) values against the 30-digit reference
    on 200 points of (0, 50], and ns per point of each against SciPy in the same run."""
    q = np.linspace(0, 50, 201)[1:]
    errors = {}
    print("\nMathieu, against numerics.mathieu_refined (30 digits) on 200 points of (0, 50], "
          "relative to max(1, |a|); ns per point on [0, min(5, verified q)], best of 5:")
    print(f"{'':<6}{'SciPy max':>10}{'at q':>7}{'verified to q':>15}{'Padé':>8}{'rows':>6}"
          f"{'emitted max':>13}"
          f"{'SciPy there':>13}{'ufunc ns':>10}{'_into ns':>10}{'SciPy ns':>10}{'ratio':>8}")
    with tempfile.TemporaryDirectory() as folder:
        for kind, m in MATHIEU:
            ref = np.array([float(mathieu_refined(kind, m, float(v))) for v in q])
            scale = np.maximum(1, np.abs(ref))
            scipy_f = mathieu_a if kind == "a" else mathieu_b
            es = np.abs(scipy_f(m, q) - ref) / scale
            generate_mathieu(kind, m, 100, Path(folder))
            mod = load_generated(Path(folder) / f"mathieu_{kind}{m}.py")
            f, f_into = getattr(mod, f"{kind}{m}"), getattr(mod, f"{kind}{m}_into")
            er = np.abs(f(q) - ref) / scale
            inside = q <= mod.LIMIT
            qs = np.random.default_rng(0).uniform(0, min(5.0, mod.LIMIT), 100_000)
            out = np.empty_like(qs)
            f(qs[:10]), f_into(out, qs)
            ufunc = best(lambda f=f, qs=qs: f(qs), 5) / qs.size * 1e9
            into = best(lambda f_into=f_into, qs=qs, out=out: f_into(out, qs), 5) / qs.size * 1e9
            small = qs[:20_000]
            scipy_ns = best(lambda m=m, small=small, g=scipy_f: g(m, small), 5) / small.size * 1e9
            degrees = "[{}/{}]".format(*mod.DEGREES)
            print(f"{kind}_{m:<4}{es.max():>10.1e}{q[np.argmax(es)]:>7.3g}{mod.LIMIT:>15.4g}"
                  f"{degrees:>8}{mod.ROWS:>6}{np.nanmax(er[inside]):>13.1e}{es[inside].max():>13.1e}"
                  f"{ufunc:>10.3g}{into:>10.3g}{scipy_ns:>10.3g}{scipy_ns / ufunc:>8.1f}")
            if (kind, m) in MATHIEU_DRAWN:
                errors[f"SciPy {kind}_{m}"] = es
                errors[f"emitted {kind}_{m}"] = er
    qs = np.random.default_rng(0).uniform(0, 5, 1_000_000)
    small = qs[:20_000]
    z = sp.Symbol("q")
    series = mathieu_series("a", 0, 100)
    lam = sp.lambdify(z, sum(sp.Rational(c.numerator, c.denominator) * z**k
                             for k, c in enumerate(series)), "numpy")
    lam_ns = best(lambda: lam(qs), 3) / qs.size * 1e9
    ref_ns = best(lambda: [mathieu_reference("a", 0, float(v)) for v in small[:200]], 1) \
        / 200 * 1e9
    print(f"\na_0(q) on q ∈ [0, 5], ns per point this run: lambdify of the order-100 series "
          f"{lam_ns:.3g}; float64 eigenvalue reference {ref_ns:.3g}")
    return q, errors


def main() -> int:
    t0 = time.perf_counter()
    if "--mathieu-only" in sys.argv[1:]:
        q, errors = mathieu_part()
        mathieu_accuracy_figure(q, errors, MATHIEU_FIGURE)
        print(f"\nwrote {MATHIEU_FIGURE} ({time.perf_counter() - t0:.0f} s)")
        return 0
    vdp = series_model("van_der_pol", ORDER)
    lc = derive_limit_cycle(vdp, ORDER)
    eps = np.array(EPS)
    refs = [cycle_reference(vdp, e) for e in EPS]
    truth = np.array([2 * np.pi / r.period for r in refs])
    print(f"references: DOP853 rtol 1e-13; largest two-tolerance difference "
          f"{max(r.accuracy for r in refs):.1e}")
    shots = {f"{rtol:g}": np.array([2 * np.pi / cycle_reference(vdp, e, rtol=rtol).period
                                    for e in EPS]) for rtol in SHOOT_RTOLS}
    shots["1e-13"] = truth * (1 + np.array([r.accuracy for r in refs]))
    forms_table(lc.omega[: FORMS_ORDER + 1], eps, truth)
    amplitude_table(lc, eps, refs)
    panels = cycle_panels(lc, eps, truth, shots)
    for title, points in panels:
        print(f"\n{title}: max relative error of ω")
        for method, label, ns, err in points:
            print(f"  {method:<10}{label:<8}{ns:>10.3g} ns (recorded){err:>10.1e}")
    cycle_timings(lc)
    mathieu = mathieu_part()
    resummed_speed_accuracy_figure(panels, mathieu, FIGURE)
    mathieu_accuracy_figure(*mathieu, MATHIEU_FIGURE)
    print(f"\nwrote {FIGURE} ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
