"""``demo``: the main job on the built-in defaults, about a minute, the long runs named."""

from __future__ import annotations

import argparse
from pathlib import Path

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import _flag_overwrite_edited, _out_folder
from .driven import _parametric_table, _subharmonic_table, parametric_json, subharmonic_json
from .series import series_table

DEMO_ORDER = 12
# NOTE: the demo's free evaluators: order 12 keeps T(A) within 1e-6 for |εA²| ≤ 0.3 and the
# LaTeX a few pages long.
DRIVEN_ORDER = 3
# NOTE: the exact μ-expansion's rational functions grow fast; order 3 keeps the derivation
# readable and the emitted A_n(ω) within 1e-5 of the true orbit at the notes' parameters.
DEMO_BALANCE_HARMONICS = 4
# NOTE: the demo's balance module: 4 odd harmonics reach 1e-7 at the notes' parameters and
# compile in seconds.


def run_demo(args: argparse.Namespace) -> int:
    """The main job on the built-in defaults: derive, emit, evaluate against exact, typeset.
    Everything it writes goes under ``--out``: evaluators and LaTeX, ``figures/``, the PDFs."""
    out = _out_folder(args.out)  # before the heavy imports: an empty --out answers at once
    import shutil
    import subprocess

    import numpy as np

    from ..charts import (
        check_plot_path,
        driven_speed_accuracy_figure,
        gallery,
        speed_accuracy_figure,
    )
    from ..compiler import generate, generate_balance, generate_driven
    from ..derive.lindstedt import derive
    from ..derive.models import model_by_name
    from ..emit.render import check_writable, load_generated
    from ..numerics.references import duffing_period_exact, pendulum_period_exact

    figures = out / "figures"
    modules = ["duffing", "pendulum", "driven", "balance"]
    check_writable(out, [*(f"{m}.py" for m in modules), "duffing_tables.tex",
                         "duffing_derivation.tex", "pendulum_tables.tex",
                         "pendulum_derivation.tex", "driven_derivation.tex",
                         "van_der_pol_slow_flow.py", "van_der_pol_slow_flow.tex",
                         "van_der_pol.py", "van_der_pol_derivation.tex"],
                   overwrite_edited=args.overwrite_edited)
    figures.mkdir(parents=True, exist_ok=True)
    check_plot_path(figures / "speed_accuracy.png")
    print(series_table(derive(model_by_name("duffing", 6), 6)))
    print(f"\nwriting the default evaluators and LaTeX into {out}/")
    for name in ("duffing", "pendulum"):
        for path in generate(name, DEMO_ORDER, out, overwrite_edited=args.overwrite_edited):
            print(f"  {path}")
    edited = args.overwrite_edited
    for path in [*generate_driven(DRIVEN_ORDER, out, overwrite_edited=edited),
                 *generate_balance(DEMO_BALANCE_HARMONICS, out, overwrite_edited=edited)]:
        print(f"  {path}")
    duf = load_generated(out / "duffing.py")
    x = np.array([-0.9, -0.5, -0.1, 0.1, 0.5, 0.9])
    exact = duffing_period_exact(1.0, x)
    print(f"\nDuffing period, order {duf.ORDER}, against 4K(m)/sqrt(1+x) (A = 1, eps = x):")
    print(f"{'x':>6} {'series T':>20} {'exact T':>20} {'rel. error':>11} {'estimate':>10}")
    for xi, ti, ei, est in zip(x, duf.period(1.0, x), exact, duf.error_estimate(1.0, x),
                               strict=True):
        print(f"{xi:>6.2f} {ti:>20.15f} {ei:>20.15f} {abs(ti / ei - 1):>11.1e} {est:>10.1e}")
    pen = load_generated(out / "pendulum.py")
    deg = np.array([5.0, 10.0, 30.0, 60.0, 90.0, 120.0])
    th = np.radians(deg)
    exact = pendulum_period_exact(th)
    drv = load_generated(out / "driven.py")
    print(f"\nDriven Duffing (eps = 0.1, f = 1, omega = 1): mu-expansion order {drv.ORDER}: "
          f"A1 = {drv.A_1(1.0, 0.1, 1.0, 0):.6f}, A3 = {drv.A_3(1.0, 0.1, 1.0, 0):.6f} "
          "(notes, numerically: 2.356, 0.0456)")
    print(f"\nGrandfather's clock: pendulum period, order {pen.ORDER}, "
          "against 4K(sin^2(theta0/2)):")
    print(f"{'theta0':>7} {'series T':>20} {'exact T':>20} {'rel. error':>11} {'s/day':>9}")
    for d, ti, ei in zip(deg, pen.period(th), exact, strict=True):
        print(f"{d:>6.0f}° {ti:>20.15f} {ei:>20.15f} {abs(ti / ei - 1):>11.1e} "
              f"{86400 * abs(ti / ei - 1):>9.1e}")
    print("\nfigures:")
    for path in gallery(figures):
        print(f"  {path}")
    # NOTE: measured costs differ run to run: these two charts are the run's own
    # (benchmarks/*speed_accuracy.py refresh the committed copies the README shows).
    print(f"  {speed_accuracy_figure(figures / 'speed_accuracy.png')}")
    print(f"  {driven_speed_accuracy_figure(figures / 'driven_speed_accuracy.png')}")
    from ..charts import ince_strutt_figure  # Hill's equation: Floquet grid and series curves

    print(f"  {ince_strutt_figure(figures / 'ince_strutt.png')}")
    _demo_limit_cycle(out, args.overwrite_edited)
    _demo_slow_flow(out, figures, args.overwrite_edited)
    _demo_parametric(figures)
    if shutil.which("pdflatex"):
        for tex in sorted(out.glob("*.tex")):
            for _ in range(2):  # longtable settles its column widths on the second pass
                subprocess.run(["pdflatex", "-interaction=batchmode", "-halt-on-error",
                                "-output-directory", str(out), str(tex)],
                               check=True, stdout=subprocess.DEVNULL)
            print(f"  typeset {tex.with_suffix('.pdf')}")
    else:
        print("\npdflatex not found: `make demo` installs it; LaTeX sources are in", out)
    return 0


DEMO_CYCLE_ORDER = 12
DEMO_CYCLE_RESUM_ORDER = 60
DEMO_CYCLE_EPS = (0.1, 1.0, 2.5, 3.5, 5.0)
DEMO_CYCLE_LONG_ORDER = 164
# NOTE: partial sums to order 12, ω resummed from the exact series to order 60 (~25 s with its
# shooting checks): verified to ε ≈ 3.75, and one point past it, where the emitted evaluator
# answers NaN.  From order 164 (Andersen & Geer's order) it reaches ε = 10 in about four
# minutes: the demo names that run instead of making it (a demo shows the tool in a minute).


def _demo_limit_cycle(out: Path, overwrite_edited: bool) -> None:
    """The demo's limit cycle: van der Pol's evaluators (the partial sum and the resummed ω,
    NaN beyond their verified ε) and its derivation, against the shot cycle."""
    import numpy as np

    from ..compiler import generate_limit_cycle
    from ..derive.models import series_model
    from ..emit.render import load_generated
    from ..numerics.references import cycle_reference, cycle_samples

    model = series_model("van_der_pol", DEMO_CYCLE_ORDER + 2)
    print(f"\nvan der Pol's limit cycle, order {DEMO_CYCLE_ORDER}, ω resummed from order "
          f"{DEMO_CYCLE_RESUM_ORDER} (lindstedt generate van_der_pol --order {DEMO_CYCLE_ORDER} "
          f"--resum-order {DEMO_CYCLE_RESUM_ORDER} --out {out}):")
    for path in generate_limit_cycle(model, DEMO_CYCLE_ORDER, out,
                                     resum_order=DEMO_CYCLE_RESUM_ORDER,
                                     overwrite_edited=overwrite_edited):
        print(f"  {path}")
    print(f"  (the longer run: --resum-order {DEMO_CYCLE_LONG_ORDER} --allow-slow verifies the "
          "resummed omega to eps = 10, in about four minutes)")
    vdp = load_generated(out / "van_der_pol.py")
    eps = np.array(DEMO_CYCLE_EPS)
    print(f"  omega against the shot cycle (DOP853); the partial sum stops at |eps| = "
          f"{vdp.RADIUS:.3g}, the resummed omega is verified to |eps| <= "
          f"{vdp.RESUMMED_LIMIT:g}; NaN beyond")
    print(f"  {'eps':>5} {'partial sum':>18} {'resummed':>18} {'shot':>18} {'rel. error':>10}")
    for e, series, resummed in zip(eps, vdp.omega(eps), vdp.omega_resummed(eps), strict=True):
        shot = 2 * np.pi / cycle_reference(model, float(e)).period
        error = f"{abs(resummed / shot - 1):>10.1e}" if np.isfinite(resummed) else f"{'-':>10}"
        print(f"  {e:>5g} {series:>18.15f} {resummed:>18.15f} {shot:>18.15f} {error}")
    if hasattr(vdp, "q_resummed"):
        e = min(2.5, vdp.Q_RESUMMED_LIMIT)
        t, shot = cycle_samples(model, e, cycle_reference(model, e), 64)
        print(f"  q_resummed(t, {e:g}) over one period against the shot orbit: max error "
              f"{np.max(np.abs(vdp.q_resummed(t, e) - shot)):.1e} ({vdp.Q_RESUMMED_HARMONICS} "
              f"harmonics, verified to |eps| <= {vdp.Q_RESUMMED_LIMIT:g}, NaN beyond)")


def _demo_slow_flow(out: Path, figures: Path, overwrite_edited: bool) -> None:
    """The demo's slow flow: van der Pol's to order 2, emitted and typeset, run from r = 0.1
    against simulation, and its two figures."""
    import numpy as np

    from ..charts import slow_flow_figures
    from ..compiler import generate_slow_flow
    from ..derive.averaging import simulate, slow_flow, transient
    from ..derive.models import REGISTRY, oscillator
    from ..emit.render import load_generated

    text = REGISTRY["van_der_pol"].equation
    osc = oscillator(text, name="van_der_pol")
    command = f'lindstedt slowflow "{text}" --name van_der_pol --order 2'
    print(f"\nthe slow flow of van der Pol to order 2 ({command} --out {out}):")
    for path in generate_slow_flow(osc, 2, command, out, overwrite_edited=overwrite_edited):
        print(f"  {path}")
    emitted = load_generated(out / "van_der_pol_slow_flow.py")
    rate = emitted.slow_flow(np.array([2.0, 0.0]), 0.1)
    print(f"  at the cycle r = 2, eps = 0.1: dr/dt = {rate[0]:.3g}, dphi/dt = {rate[1]:.6f} "
          "(-eps^2/16 = -0.000625)")
    flow, eps = slow_flow(osc, 2), 0.1
    t = np.linspace(0.0, 80.0, 9)
    r_sim = np.hypot(*simulate(osc, eps, 0.1, 0.0, t))
    r_avg = np.hypot(*transient(flow, eps, 0.1, 0.0, t))
    print(f"  from r = 0.1 at eps = {eps}:")
    print(f"  {'t':>6}  {'r (simulation)':>15}  {'r (slow flow)':>14}")
    for ti, a, b in zip(t, r_sim, r_avg, strict=True):
        print(f"  {ti:>6.0f}  {a:>15.6f}  {b:>14.6f}")
    for path in slow_flow_figures(figures):
        print(f"  {path}")


DEMO_SUBHARMONIC = (0.1, 0.5, 1.3)
# NOTE: (ε, f, ω) where the notes' q₀ Hill test calls the "−" root stable and it is not.


def _demo_parametric(figures: Path) -> None:
    """The demo's parametric block: the response figure under ``figures``, the tongue and
    onsets, and one subharmonic where the full Hill equation corrects the notes' verdict."""
    from ..charts import PARAMETRIC_FIGURE, parametric_figure

    data = parametric_json(*PARAMETRIC_FIGURE, points=2)
    print(f"  {parametric_figure(*PARAMETRIC_FIGURE, figures / 'parametric.png')}")
    print()
    for line in [*_parametric_table(data)[:5], *_subharmonic_table(subharmonic_json(
            *DEMO_SUBHARMONIC))]:
        print(line)


def arguments_demo(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt demo``'s arguments."""
    p = sub.add_parser("demo", help="derive, emit, evaluate and typeset the built-in defaults",
                       description="The main job on the built-in defaults; writes only under "
                       "--out.")
    p.add_argument("--out", default="out", metavar="DIR",
                   help="output folder for evaluators, LaTeX, PDFs and figures/ (default out/)")
    _flag_overwrite_edited(p)
    return p
