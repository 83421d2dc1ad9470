"""``demo``: the main job on the built-in defaults, about a minute, the long runs named."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import _flag_overwrite_edited, _out_folder
from .system import periodic_json, periodic_table

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
    Everything it writes goes under ``--out``: evaluators and LaTeX, ``figures/``, the PDFs.
    The longer runs (every figure, the resummed limit cycle) are named at the end."""
    out = _out_folder(args.out)  # before the heavy imports: an empty --out answers at once
    import shutil
    import subprocess

    import numpy as np

    from ..charts import GALLERY, check_plot_path
    from ..compiler import generate, generate_balance, generate_driven
    from ..derive.lindstedt import derive, validity
    from ..derive.models import model_by_name
    from ..emit.render import check_writable, load_generated
    from ..numerics.references import duffing_period_exact, pendulum_period_exact

    figures = out / "figures"
    modules = ["duffing", "pendulum", "driven", "balance"]
    check_writable(out, [*(f"{m}.py" for m in modules), "duffing_tables.tex",
                         "duffing_derivation.tex", "pendulum_tables.tex",
                         "pendulum_derivation.tex", "driven_derivation.tex",
                         "van_der_pol_slow_flow.py", "van_der_pol_slow_flow.tex"],
                   overwrite_edited=args.overwrite_edited)
    figures.mkdir(parents=True, exist_ok=True)
    drawn = [(name, draw) for name, draw in GALLERY if name in DEMO_FIGURES]
    for name, _ in drawn:
        check_plot_path(figures / name)
    duffing6 = derive(model_by_name("duffing", 6), 6)
    print(periodic_table(periodic_json(duffing6, validity(duffing6))))
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
    print(f"\nGrandfather's clock: pendulum period, order {pen.ORDER}, "
          "against 4K(sin^2(theta0/2)):")
    print(f"{'theta0':>7} {'series T':>20} {'exact T':>20} {'rel. error':>11} {'s/day':>9}")
    for d, ti, ei in zip(deg, pen.period(th), exact, strict=True):
        print(f"{d:>6.0f}° {ti:>20.15f} {ei:>20.15f} {abs(ti / ei - 1):>11.1e} "
              f"{86400 * abs(ti / ei - 1):>9.1e}")
    _demo_balance(load_generated(out / "balance.py"))
    _demo_limit_cycle()
    _demo_slow_flow(out, args.overwrite_edited)
    print("\nfigures:")
    for name, draw in drawn:
        print(f"  {draw(figures / name)}")
    if shutil.which("pdflatex"):
        for tex in sorted(out.glob("*.tex")):
            for _ in range(LATEX_PASSES):  # again while LaTeX asks (a longtable's widths)
                subprocess.run(["pdflatex", "-interaction=batchmode", "-halt-on-error",
                                "-output-directory", str(out), str(tex)],
                               check=True, stdout=subprocess.DEVNULL)
                if not RERUN.search((out / f"{tex.stem}.log").read_text(errors="replace")):
                    break
            print(f"  typeset {tex.with_suffix('.pdf')}")
    else:
        print("\npdflatex not found: `make demo` installs it; LaTeX sources are in", out)
    print("\nthe longer runs:")
    for line in LONGER_RUNS:
        print(f"  {line}")
    return 0


LATEX_PASSES = 3
RERUN = re.compile(r"Rerun (LaTeX|to get)")
# NOTE: pdflatex runs again only while its log asks (longtable: "Table widths have changed.
# Rerun LaTeX."), as latexmk does: a document without a table is typeset once.
DEMO_FIGURES = ("response.png", "mixing.png")
# NOTE: two of the README's figures (~10 s together); `make figures` draws every one.
LONGER_RUNS = (
    "make figures    # every figure of the README: subharmonics, validity maps, Ince-Strutt, ...",
    "lindstedt generate van_der_pol --order 12 --resum-order 60 --out out   # the cycle's "
    "evaluators, omega resummed and verified to eps = 3.75 (~1 min)",
    "lindstedt generate van_der_pol --order 12 --resum-order 164 --allow-slow --out out   "
    "# to eps = 10 (~4 min)",
    "lindstedt generate driven --order 3 --out out; python -c 'import driven'   # the "
    "mu-expansion's evaluators compiled (~15 s)",
)


def _demo_balance(balance: object) -> None:
    """The notes' driven Duffing (ε = 0.1, f = 1, ω = 1, undamped) by the emitted harmonic
    balance, from the one-harmonic root (3/4)εA³ = f."""
    import numpy as np

    eps, force, omega = 0.1, 1.0, 1.0
    x0 = np.zeros(len(balance.UNKNOWNS))
    x0[0] = (4 * force / (3 * eps)) ** (1 / 3)
    x, ok = balance.newton(x0, omega, eps, force, 0.0)
    print(f"\nDriven Duffing (eps = {eps}, f = {force}, omega = {omega}): harmonic balance, "
          f"{balance.HARMONICS} odd harmonics{'' if ok else ' (not converged)'}: "
          f"A1 = {x[0]:.6f}, A3 = {x[1]:.6f} (the notes' mu-expansion: 2.356, 0.0456)")


DEMO_CYCLE_ORDER = 12
DEMO_CYCLE_EPS = (0.1, 0.5, 1.0)
# NOTE: van der Pol's partial sums to order 12, inside their radius (|ε| < 3.8) where each
# shot cycle costs about a second.


def _demo_limit_cycle() -> None:
    """van der Pol's limit cycle: the exact series' partial sum of ω against the shot cycle."""
    import numpy as np

    from ..derive.cycles import derive_limit_cycle
    from ..derive.models import series_model
    from ..numerics.references import cycle_reference

    model = series_model("van_der_pol", DEMO_CYCLE_ORDER + 2)
    cycle = derive_limit_cycle(model, DEMO_CYCLE_ORDER)
    print(f"\nvan der Pol's limit cycle, order {DEMO_CYCLE_ORDER}: omega = "
          + " ".join(f"{'+' if c > 0 else '-'} {abs(c)} eps^{j}" if j else f"{c}"
                     for j, c in enumerate(cycle.omega[:5]) if c) + " + ...")
    print(f"  {'eps':>5} {'partial sum':>18} {'shot (DOP853)':>18} {'rel. error':>10}")
    for e in DEMO_CYCLE_EPS:
        series = float(sum(c * e**j for j, c in enumerate(cycle.omega)))
        shot = 2 * np.pi / cycle_reference(model, e).period
        print(f"  {e:>5g} {series:>18.15f} {shot:>18.15f} {abs(series / shot - 1):>10.1e}")


def _demo_slow_flow(out: Path, overwrite_edited: bool) -> None:
    """The demo's slow flow: van der Pol's to order 2, emitted and typeset, run from r = 0.1
    against simulation."""
    import numpy as np

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


def arguments_demo(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt demo``'s arguments."""
    p = sub.add_parser("demo", help="derive, emit, evaluate and typeset the built-in defaults",
                       description="The main job on the built-in defaults; writes only under "
                       "--out.")
    p.add_argument("--out", default="out", metavar="DIR",
                   help="output folder for evaluators, LaTeX, PDFs and figures/ (default out/)")
    _flag_overwrite_edited(p)
    return p
