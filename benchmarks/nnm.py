"""Nonlinear normal modes: derivation time, accuracy against shooting, and the emitted
backbone against a numeric continuation of the same backbone by shooting (SciPy's DOP853 and
the package's Newton, numerics.references.mode_orbit), in one run.

    .venv/bin/python benchmarks/nnm.py

Targets (docs/benchmarks.md): Kerschen's 2-DOF system, modes 1 and 2, order 20 in ≤ 1 s and
order 60 in ≤ 30 s; the order-12 backbone within 1e-8 of shooting at A = 0.1 and 1e-5 at
A = 0.3; the 8-mass FPU-β chain's lowest mode at order 10 in ≤ 10 s; the emitted backbone
≥ 10⁴× faster per point than shooting the orbit.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from lindstedt.derive.nnm import normal_mode
from lindstedt.derive.system import parse_system
from lindstedt.numerics.references import mode_orbit

KERSCHEN = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"


def fpu(n: int = 8) -> str:
    """The FPU-β chain of ``n`` unit masses with fixed ends, β = 1."""
    eqs = []
    for i in range(1, n + 1):
        left = f"x{i - 1}" if i > 1 else "0"
        right = f"x{i + 1}" if i < n else "0"
        eqs.append(f"x{i}'' + 2*x{i} - {left} - {right} + (x{i} - {left})**3 "
                   f"- ({right} - x{i})**3 = 0")
    return "; ".join(eqs)


def shooter(text: str):
    """The orbit through x1(0) = A with zero velocities (the package's reference,
    :func:`numerics.references.mode_orbit`): ``(other coordinates at t = 0, T/2)``."""
    system = parse_system(text)

    def shoot(A: float, guess: np.ndarray) -> np.ndarray:
        orbit = mode_orbit(system, A, guess)
        if not orbit.converged:
            raise RuntimeError(f"A = {A}: the shot orbit did not converge")
        return np.append(orbit.start[1:], orbit.period / 2)

    return shoot


def series_values(mode, A: float) -> tuple[float, np.ndarray]:
    """T(A) and every coordinate at t = 0, summed from the exact series in floats."""
    _, period, starts = mode.evaluate(A)
    return float(period), starts


def timed(fn, repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    system = parse_system(KERSCHEN)
    print("derivation (best of 3, in-process; the command's wall time below)")
    print(f"{'system':<28}{'mode':>5}{'order':>7}{'seconds':>10}{'target':>9}")
    for mode in (1, 2):
        for order, target in ((20, 1.0), (60, 30.0)):
            seconds = timed(lambda m=mode, k=order: normal_mode(system, m, k).omega(),
                            1 if order > 20 else 3)
            print(f"{'Kerschen 2-DOF':<28}{mode:>5}{order:>7}{seconds:>10.3f}{target:>9.0f}")
    chain = parse_system(fpu())
    seconds = timed(lambda: normal_mode(chain, 1, 10).omega(), 1)
    print(f"{'FPU-beta, 8 masses':<28}{1:>5}{10:>7}{seconds:>10.3f}{10:>9.0f}")
    for mode in (1, 2):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "lindstedt", "nnm", KERSCHEN, "--mode", str(mode),
                        "--order", "20", "--json"], check=True, capture_output=True)
        print(f"  `lindstedt nnm KERSCHEN --mode {mode} --order 20 --json`: "
              f"{time.perf_counter() - start:.2f} s wall, start-up and output included")

    print("\naccuracy of the order-12 backbone against shooting (relative error of T)")
    print(f"{'mode':>5}{'A':>6}{'|T/T_shot - 1|':>17}{'|x2(0) err|/A':>15}{'target':>9}")
    shoot = shooter(KERSCHEN)
    for mode in (1, 2):
        series = normal_mode(system, mode, 12)
        for A, target in ((0.1, 1e-8), (0.3, 1e-5)):
            period, starts = series_values(series, A)
            x = shoot(A, np.array([*starts[1:], period / 2]))
            print(f"{mode:>5}{A:>6}{abs(period / (2 * x[-1]) - 1):>17.1e}"
                  f"{abs(starts[1] - x[0]) / A:>15.1e}{target:>9.0e}")

    print("\nthe emitted backbone against a shooting continuation of the same backbone (mode 2)")
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, "-m", "lindstedt", "generate", KERSCHEN, "--mode", "2",
                        "--order", "12", "--out", tmp], check=True, capture_output=True)
        spec = importlib.util.spec_from_file_location("mode2", Path(tmp) / "mode2.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        A = np.linspace(0.01, 0.6, 1_000_000)
        out = np.empty_like(A)
        module.period_into(out, A)
        ns = timed(lambda: module.period_into(out, A), 5) / A.size * 1e9
        series = normal_mode(system, 2, 12)
        amplitudes = np.linspace(0.01, 0.6, 30)
        guess = None
        errors, start = [], time.perf_counter()
        for a in amplitudes:  # natural continuation: each orbit seeds the next
            if guess is None:
                period, starts = series_values(series, a)
                guess = np.array([*starts[1:], period / 2])
            guess = shoot(a, guess)
            errors.append(abs(module.period(a) / (2 * guess[-1]) - 1))
        per_orbit = (time.perf_counter() - start) / amplitudes.size
        print(f"  emitted period_into: {ns:.1f} ns per point (10^6 points)")
        print(f"  shooting continuation: {per_orbit * 1e3:.1f} ms per orbit ({amplitudes.size} "
              "orbits, each seeded by the last)")
        print(f"  ratio: {per_orbit * 1e9 / ns:,.0f}x per point (target >= 10^4)")
        print(f"  radius of the series in y = A^2: {module.RADIUS:.3f} (A <= "
              f"{np.sqrt(module.RADIUS - module.RADIUS_SPREAD):.3f}); error of the order-12 "
              f"backbone along the continuation: max {max(errors):.1e} (A = "
              f"{amplitudes[int(np.argmax(errors))]:.2f})")
        print("  cheaper where: the series everywhere inside its radius (one evaluation "
              "against one shot orbit); shooting where the series stops (past the radius, or "
              "near an internal resonance, which the series refuses)")


if __name__ == "__main__":
    main()
