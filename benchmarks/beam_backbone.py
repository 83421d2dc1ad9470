"""The von Kármán beam of ``examples/beam_model.py``: its SSM backbone against full-order
shooting of the conservative beam.

    .venv/bin/python benchmarks/beam_backbone.py [--elements 8] [--orders 3,5,7,9]

What is compared.  The steel strip of the example (1 m × 20 mm × 2 mm, clamped–clamped),
meshed by ``--elements`` elements, written with ``--zeta 0`` (``C = 0``) into a model folder
and read back by ``read_model``, exactly as ``lindstedt ssm --model DIR`` reads it.  The SSM of
mode 1 is computed undamped at each order K; its backbone is the curve (max |w(L/2)| over a
period, ω(ρ)).  The reference is the family of periodic orbits of the same conservative
``M x'' + K x + f(x) = 0``, every coordinate kept (``tests/ssm_reference.py``:
``backbone``): half-period shooting from rest with the period unknown (``v(0) = 0`` the phase
condition, ``w(L/2)`` at ``t = 0`` the amplitude), Newton with the variational equations,
continuation in the amplitude from the linear mode, classical RK4 with a fixed step below
the stiffest (axial) mode's stability limit, compiled by numba; each guess with the modes
above 3ω₀ (the axial ones) in static equilibrium.  Each orbit is judged by its residual: one
whole period integrated afresh with half the step, ``|(x(T) − x(0), v(T)/ω)| / |x(0)|``.
``--figure PNG`` draws the backbones and the errors (docs/figures/beam_backbone.png:
``--figure docs/figures/beam_backbone.png``; the same bytes every run).
``--check`` shoots the largest amplitude again by SciPy's adaptive DOP853 (rtol 1e-12; slow
on this stiff model: about two minutes) from the RK4 orbit: Newton's steps, the whole
period's residual at rtol 1e-13, both frequencies.
The SSM's ω at a shooting amplitude A is ``ω(ρ)`` at the ρ where its amplitude equals A
(Brent's method).

Everything printed is deterministic but the wall times (their own lines, marked ``time``).
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

ROOT = Path(__file__).resolve().parent.parent
AMPLITUDES = [k * 1e-4 for k in range(1, 9)]  # w(L/2), m: the frequency rises by up to ~8 %


def load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def ssm_omega(red, A: float, output: int) -> tuple[float, float]:
    """``(ω, ρ)`` of the SSM's backbone where ``max |x_output| = A``."""
    def gap(rho: float) -> float:
        return float(red.amplitude(np.array([rho]), np.array([output]))[0, 0]) - A

    hi = A
    while gap(hi) < 0:  # the amplitude grows with ρ (about 2.8 ρ here)
        hi *= 2
    rho = brentq(gap, 0.0, hi, xtol=1e-16, rtol=1e-14)
    return float(red.omega(np.array([rho]))[0]), rho


def figure(path: Path, reductions: dict, orbits: list, out: int, w0: float) -> None:
    """Left: ω/ω₀ against max |w(L/2)| — the SSM at each K up to 1.5 times the largest
    amplitude shot (inside 90 % of its estimated radius), the shooting orbits as dots; right:
    the relative error of the SSM's ω against the amplitude, by K."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    A = np.array(AMPLITUDES)
    top = 1.5 * A[-1]
    for K, red in reductions.items():
        rho = np.linspace(0.0, 0.9 * red.radius, 400)
        amp = red.amplitude(rho, np.array([out]))[:, 0]
        keep = np.cumprod(amp <= top).astype(bool)  # up to 1.5 times the largest amplitude
        left.plot(red.omega(rho[keep]) / w0, amp[keep] * 1e3, label=f"SSM, K = {K}", lw=1.2)
        err = [abs(ssm_omega(red, a, out)[0] / o.omega - 1) for a, o in zip(A, orbits,
                                                                            strict=True)]
        right.loglog(A * 1e3, np.maximum(err, 1e-16), "o-", label=f"K = {K}", ms=4)
    left.plot([o.omega / w0 for o in orbits], A * 1e3, "ko", ms=4,
              label="full-order shooting")
    left.set_xlabel(r"$\omega/\omega_0$")
    left.set_ylabel("max |w(L/2)| [mm]")
    left.set_title("backbone of the clamped-clamped beam (8 elements, C = 0)")
    left.legend(fontsize=8)
    right.set_xlabel("max |w(L/2)| [mm]")
    right.set_ylabel(r"$|\omega_{SSM}/\omega_{shooting} - 1|$")
    right.set_title("relative error of the SSM's frequency")
    right.legend(fontsize=8)
    right.grid(True, which="major", alpha=0.3)
    right.set_xticks([0.1, 0.2, 0.4, 0.8], ["0.1", "0.2", "0.4", "0.8"])
    right.minorticks_off()
    fig.tight_layout()
    fig.savefig(path, dpi=100, metadata={"Software": None})
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=8)
    parser.add_argument("--orders", default="3,5,7,9")
    parser.add_argument("--figure", type=Path, help="write the backbones and errors (PNG)")
    parser.add_argument("--check", action="store_true",
                        help="shoot the largest amplitude again by DOP853 (about a minute)")
    args = parser.parse_args(argv)
    orders = [int(k) for k in args.orders.split(",")]

    bm = load("beam_model", ROOT / "examples" / "beam_model.py")
    sys.path.insert(0, str(ROOT / "tests"))
    from lindstedt.analysis.ssm import ssm
    from lindstedt.derive.system import read_model
    from ssm_reference import backbone, free_orbit

    beam = bm.Beam(elements=args.elements)
    model = bm.assemble(beam, zeta=0.0)
    out = beam.midspan
    print(f"von Karman beam (examples/beam_model.py defaults), {beam.elements} elements, "
          f"n = {beam.size} DOFs, C = 0; output w(L/2) = DOF {out}")
    print(f"lowest bending {model.bending[0]:.10g} rad/s, lowest axial {model.axial[0]:.6g}, "
          f"axial/bending {model.axial[0] / model.bending[0]:.1f}")

    with tempfile.TemporaryDirectory() as folder:
        bm.write_folder(model, Path(folder))
        system = read_model(folder)
    reductions, ssm_times = {}, {}
    for K in orders:
        t = time.perf_counter()
        reductions[K] = ssm(system, 1, K)
        ssm_times[K] = time.perf_counter() - t
    for K in orders:
        red = reductions[K]
        print(f"SSM K = {K}: radius in rho {red.radius:.4g} (amplitude there "
              f"{float(red.amplitude(np.array([red.radius]), np.array([out]))[0, 0]):.4g} m), "
              f"worst residual {max(red.residual):.1e}")

    equation, factors, coefficient = model.terms
    terms = [(i, [k for k in f if k >= 0], c) for i, f, c in
             zip(equation.tolist(), factors.tolist(), coefficient.tolist(), strict=True)]
    t = time.perf_counter()
    orbits = backbone(model.mass.toarray(), model.stiffness.toarray(), terms, out, AMPLITUDES)
    shooting_time = time.perf_counter() - t
    w0 = float(model.bending[0])
    print(f"shooting: RK4, {orbits[0].steps} steps a period (Newton), the judge twice as many")

    head = f"{'A [m]':>8} {'omega shooting':>16} {'residual':>9} {'shift':>7}"
    head += "".join(f" {'K=' + str(K):>14}" for K in orders)
    head += "".join(f" {'err K=' + str(K):>9}" for K in orders) + f" {'rho/radius':>10}"
    print(head)
    for A, orbit in zip(AMPLITUDES, orbits, strict=True):
        assert abs(orbit.amplitude[out] - A) <= 1e-9 * A  # the maximum is at t = 0
        row = f"{A:8.1e} {orbit.omega:16.10f} {orbit.residual:9.1e} {orbit.omega / w0 - 1:7.2%}"
        results = {K: ssm_omega(reductions[K], A, out) for K in orders}
        row += "".join(f" {results[K][0]:14.8f}" for K in orders)
        row += "".join(f" {results[K][0] / orbit.omega - 1:+9.1e}" for K in orders)
        top = orders[-1]
        row += f" {results[top][1] / reductions[top].radius:10.2f}"
        print(row)
    print(f"(rho/radius: the K = {orders[-1]} SSM's rho at A over its estimated radius)")
    if args.figure:
        figure(args.figure, reductions, orbits, out, w0)
        print(f"figure: {args.figure}")
    if args.check:
        last = orbits[-1]
        t = time.perf_counter()
        again = free_orbit(model.mass.toarray(), model.stiffness.toarray(), terms, out,
                           AMPLITUDES[-1], last.y0[:beam.size], last.omega, method="DOP853")
        check_time = time.perf_counter() - t
        print(f"check at A = {AMPLITUDES[-1]:.1e}: from the RK4 orbit, DOP853's Newton took "
              f"{again.newton} half period(s), its residual over a whole period "
              f"{again.residual:.1e}; omega {again.omega:.15g} against RK4's "
              f"{last.omega:.15g} (relative {again.omega / last.omega - 1:+.1e})")
    print("time: SSM " + ", ".join(f"K = {K} {ssm_times[K]:.2f} s" for K in orders)
          + f"; shooting {len(orbits)} orbits {shooting_time:.1f} s "
          f"({shooting_time / len(orbits):.1f} s an orbit)"
          + (f"; DOP853 check {check_time:.1f} s" if args.check else ""))
    print("time: each orbit " + ", ".join(f"{A * 1e3:.1f} mm {o.seconds:.1f} s"
                                          for A, o in zip(AMPLITUDES, orbits, strict=True)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
