"""A driven, damped 2-DOF system's response (``response SYSTEM``): the command's wall time, the
balance's accuracy and cost per point against shooting the same orbits, harmonic by harmonic,
and a shooting continuation of the same stretch of curve as the baseline, in one run.

    .venv/bin/python benchmarks/response_system.py

Kerschen's system with damping 0.05 on both coordinates and f cos ωt on the first, f = 3/10:
two resonances, four folds.  The baseline traces ω ∈ [0.5, 1.1] (the stable branch below the
first fold) by natural-parameter continuation, each point shot by Newton on the period map
(DOP853 at 1e-11, :func:`numerics.shooting.shoot_system`) from the previous one.
"""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
from lindstedt.analysis.polynomial import PolynomialBalance
from lindstedt.analysis.systems import SystemBalance, driven_problem, response
from lindstedt.derive.system import parse_system
from lindstedt.numerics.floquet import variational_multipliers
from lindstedt.numerics.integrate import PolynomialField
from lindstedt.numerics.shooting import shoot_system

SYSTEM = ("x1'' + 0.05*x1' + 2*x1 - x2 + x1**3/2 = f*cos(w*t); "
          "x2'' + 0.05*x2' + 2*x2 - x1 = 0")
VALUES = {"f": "3/10"}


def command_seconds(*extra: str) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "lindstedt", "response", SYSTEM, "--param", "f=3/10",
                    *extra], check=True, capture_output=True)
    return time.perf_counter() - start


def _matched(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance between two sets of multipliers, each matched to its nearest."""
    return float(max(np.min(np.abs(b - z)) for z in a))


def main() -> None:
    system = parse_system(SYSTEM, VALUES, driven=True)
    field = PolynomialField.of(system.equations())
    drive = np.array([float(d) for d in system.drive])
    omegas = np.linspace(0.5, 1.1, 25)

    # the baseline: a shooting continuation of the stable branch below the first fold
    start = time.perf_counter()
    guess = np.zeros(4)
    shots = []
    for w in omegas:
        orbit = shoot_system(field, drive, float(w), guess, harmonics=15)
        guess = orbit.initial
        shots.append(orbit)
    shooting = (time.perf_counter() - start) / len(omegas)

    print(f"{'harmonics N':>12} {'s per point':>12} {'vs shooting':>12} "
          f"{'max |harmonic error|':>22} {'multipliers error':>18}")
    for N in (1, 2, 4, 8):
        sb = SystemBalance.of(system, N)
        fine: PolynomialBalance = sb.fine
        x = fine.refined(sb.coarse, sb.solutions(float(omegas[0]))[0][0]) \
            if N > 1 else sb.solutions(float(omegas[0]))[0][0]
        start = time.perf_counter()
        found = []
        for w in omegas:  # the same stretch by Newton from the previous point (no arclength)
            x, converged, _ = fine.solve(x, float(w))
            if not converged:
                raise RuntimeError(f"N = {N}: the balance did not converge at w = {w}")
            found.append(x)
        sb.multiplier(np.array(found), omegas)  # the verdict, as the command computes it
        per_point = (time.perf_counter() - start) / len(omegas)
        error = 0.0
        for x, orbit in zip(found, shots, strict=True):
            for c, (A, B) in enumerate(orbit.coordinates):
                a, b = fine.amplitudes(x, c)
                error = max(error, *(abs(A.get(h, 0.0) - a.get(h, 0.0)) for h in A),
                            *(abs(B.get(h, 0.0) - b.get(h, 0.0)) for h in B))
        floquet = 0.0  # every multiplier (complex), against the shot orbit's monodromy
        for x, w, orbit in zip(found[::6], omegas[::6], shots[::6], strict=True):
            gx, gv = fine.linearization(x, float(w), 2048)
            lam = variational_multipliers(gx[None], gv[None], np.array([w]))[0]
            floquet = max(floquet, _matched(lam, orbit.multipliers))
        print(f"{N:>12} {per_point:>12.2e} {shooting / per_point:>11.0f}× "
              f"{error:>22.1e} {floquet:>18.1e}")
    print(f"{'shooting':>12} {shooting:>12.2e} {'1':>11}× {'(reference)':>22}")

    for N in (4, 8):
        start = time.perf_counter()
        r = response(driven_problem(SYSTEM, VALUES), N)
        inproc = time.perf_counter() - start
        worst = max(c.error for c in r.checks)
        print(f"response SYSTEM, N = {N}: {len(r.cont.omega)} points, folds "
              f"{', '.join(f'{w:.8f}' for w in r.cont.folds)}; in-process {inproc:.2f} s, "
              f"the command {command_seconds('--harmonics', str(N), '--json'):.2f} s wall; "
              f"shot checks {len(r.checks)}, largest harmonic difference {worst:.1e}")


if __name__ == "__main__":
    main()
