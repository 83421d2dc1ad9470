"""Spectral submanifolds (`lindstedt ssm`, `generate --ssm`): the issue's targets, each beside
a baseline measured in the same run.

    .venv/bin/python benchmarks/ssm.py            # every part (about 3 minutes on 2 cores)
    .venv/bin/python benchmarks/ssm.py --quick    # without the 10⁵-mass chain

1. A 2-DOF damped pair at order 15, floating point: the command's wall time (start-up and
   output included), undriven and driven (500 frequencies), beside the imports it cannot
   avoid; the exact ground's derivation (``derive.ssm_exact``) in process.
2. Graded chains of masses with cubic springs and Rayleigh damping, written as model folders
   (``--model DIR``): 1 000 masses at order 7, 10 000 at order 5 (driven: with the 500-point
   forced response), 10⁵ at order 5 undriven (the SSM and its backbone) — the
   command's wall time and peak resident memory (``/usr/bin/time``'s, else getrusage).  The
   stiffness grows 1 → 4 and the mass 1 → 3 along the chain: ω₃/ω₁ = 2.93 and ω₅/ω₁ = 4.87,
   away from 1:3 and 1:5 (a uniform chain's ω₃/ω₁ is 2.996).
3. A forced response of 500 drive frequencies from the reduced model, in process (the
   analysis and the emitted module's ``frc``), against ``response SYSTEM`` (the full-order
   harmonic balance, every branch) on the same pair: the wall-time ratio and the peak's
   agreement.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sparse
from scipy.io import mmwrite

PAIR = ("x1'' + 0.02*x1' + 2*x1 - x2 + x1**3 = f*cos(w*t); "
        "x2'' + 0.02*x2' + 2*x2 - x1 + 0.5*x2**2 = 0")
LINDSTEDT = [sys.executable, "-m", "lindstedt"]


def chain_folder(n: int, folder: Path, zeta: float = 0.01, force: float = 1e-3) -> int:
    """A graded chain of ``n`` masses between two walls, cubic springs ``k_j(1 + d²)``,
    Rayleigh damping ``ζ`` on the two lowest modes, driven at its middle mass; returns that
    mass's index."""
    from scipy.sparse.linalg import eigsh

    folder.mkdir(parents=True, exist_ok=True)
    s = np.arange(n + 1) / n
    k = 1 + 3 * s**2
    m = 1 + 2 * np.arange(n) / n
    K = sparse.diags([k[:-1] + k[1:], -k[1:-1], -k[1:-1]], [0, 1, -1], format="coo")
    M = sparse.diags(m, format="coo")
    w = np.sqrt(np.sort(eigsh(K.tocsc(), 2, M.tocsc(), sigma=0)[0]))
    alpha, beta = 2 * zeta * w[0] * w[1] / (w[0] + w[1]), 2 * zeta / (w[0] + w[1])
    mmwrite(folder / "M.mtx", M)
    mmwrite(folder / "K.mtx", K)
    mmwrite(folder / "C.mtx", (alpha * M + beta * K).tocoo())
    lines = []
    for j in range(n + 1):  # spring j joins x_(j−1) and x_j; d = x_j − x_(j−1) (walls: 0)
        left, right = j - 1, j
        if left >= 0 and right < n:
            cube = [((right,) * 3, 1), ((right, right, left), -3), ((right, left, left), 3),
                    ((left,) * 3, -1)]
        else:
            cube = [((right,) * 3, 1)] if right < n else [((left,) * 3, -1)]
        for idx, c in cube:
            for row, sign in ((right, 1), (left, -1)):
                if 0 <= row < n:
                    lines.append(f"{row} {idx[0]} {idx[1]} {idx[2]} {float(sign * c * k[j])!r}")
    (folder / "nonlinear.txt").write_text("\n".join(lines) + "\n")
    (folder / "drive.txt").write_text(f"{n // 2} {force!r}\n")
    return n // 2


def timed(args: list[str]) -> tuple[float, float, str]:
    """Wall seconds, peak resident MB and stdout of one command."""
    time_bin = shutil.which("time") or "/usr/bin/time"
    if Path(time_bin).exists():
        with tempfile.NamedTemporaryFile("r") as log:
            start = time.perf_counter()
            done = subprocess.run([time_bin, "-f", "%M", "-o", log.name, *args],
                                  capture_output=True, text=True, check=True)
            seconds = time.perf_counter() - start
            return seconds, int(Path(log.name).read_text().split()[-1]) / 1024, done.stdout
    start = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - start
    return seconds, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024, done.stdout


def median_of(args: list[str], runs: int = 3) -> float:
    return float(np.median([timed(args)[0] for _ in range(runs)]))


def part_pair() -> None:
    print("## 1. a 2-DOF pair at order 15")
    undriven = PAIR.replace("f*cos(w*t)", "0")
    seconds = median_of([*LINDSTEDT, "ssm", undriven, "--mode", "1", "--order", "15"])
    print(f"ssm PAIR --mode 1 --order 15, undriven (floating point, backbone, table): "
          f"{seconds:.2f} s wall (median of 3; target ≤ 1 s)")
    seconds = median_of([*LINDSTEDT, "ssm", PAIR, "--param", "f=1/100", "--mode", "1",
                         "--order", "15", "--omega", "0.9:1.1"])
    print(f"ssm PAIR --mode 1 --order 15 --omega 0.9:1.1 (the 500-point forced response, its "
          f"peaks): {seconds:.2f} s wall (median of 3)")
    startup = median_of([*LINDSTEDT, "--version"])
    print(f"  of which the interpreter's and the package's start-up (`lindstedt --version`): "
          f"{startup:.2f} s")
    imports = median_of([sys.executable, "-c", "import numpy, scipy.sparse, sympy"])
    print(f"  and NumPy, SciPy's sparse matrices and SymPy (the system's parse) imported alone: "
          f"{imports:.2f} s")
    try:
        from lindstedt.derive.ssm_exact import exact_gamma
        from lindstedt.derive.system import parse_system
    except ImportError:
        return
    system = parse_system(PAIR.replace("0.02", "1/50").replace("0.5", "1/2"),
                          {"f": "1/100"}, driven=True)
    for order in (7, 15):
        start = time.perf_counter()
        exact_gamma(system, 1, order)
        print(f"  the exact ground (derive.ssm_exact) to order {order}: "
              f"{time.perf_counter() - start:.2f} s in process")


def part_chains(sizes: list[tuple[int, int, bool]]) -> None:
    print("## 2. graded chains from model folders")
    for n, order, driven in sizes:
        with tempfile.TemporaryDirectory() as tmp:
            middle = chain_folder(n, Path(tmp) / "chain")
            if not driven:  # the SSM and its backbone alone
                (Path(tmp) / "chain" / "drive.txt").unlink()
            seconds, mb, out = timed([*LINDSTEDT, "ssm", "--model", str(Path(tmp) / "chain"),
                                      "--order", str(order), "--output", str(middle),
                                      "--json", "--allow-slow"])
            data = json.loads(out)
            near = data["near_resonances"]
            print(f"{n} masses, order {order}{'' if driven else ', undriven'}: {seconds:.1f} s "
                  f"wall, {mb:.0f} MB peak "
                  f"resident; omega0 = {data['linear']['omega0']:.6g}, worst backward error "
                  f"{max(data['residual']):.1e}, near resonances: "
                  + (", ".join(f"p1^{q['monomial'][0]} p2^{q['monomial'][1]} divisor "
                               f"{q['relative']:.3f}" for q in near) or "none"))


def part_response() -> None:
    print("## 3. a 500-point forced response: the reduced model against the full balance")
    from lindstedt.analysis.ssm import ssm
    from lindstedt.analysis.ssm_forced import forced_response, forcing_table
    from lindstedt.derive.system import parse_system

    system = parse_system(PAIR, {"f": "1/100"}, driven=True)
    model = ssm(system, 1, 11)
    omegas = np.linspace(0.95, 1.05, 500)
    runs, tables = [], []
    for _ in range(3):
        start = time.perf_counter()
        forcing_table(model, omegas, np.arange(2))
        tables.append(time.perf_counter() - start)
        start = time.perf_counter()
        response = forced_response(model, omegas, np.arange(2))
        runs.append(time.perf_counter() - start)
    top = response.peaks[0]
    print(f"analysis.ssm_forced.forced_response at order 11, 500 frequencies: "
          f"{np.median(runs) * 1e3:.0f} ms in all (median of 3), of which the non-autonomous "
          f"SSM on its Chebyshev nodes {np.median(tables) * 1e3:.0f} ms; peak max|x1| = "
          f"{top.amplitude:.7f} at omega = {top.omega:.6f}")
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([*LINDSTEDT, "generate", PAIR, "--param", "f=1/100", "--ssm", "1",
                        "--order", "11", "--omega", "0.95:1.05", "--out", tmp], check=True,
                       capture_output=True)
        spec = importlib.util.spec_from_file_location("ssm1", Path(tmp) / "ssm1.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        module.frc(1.0, 1.0)  # compiled (or loaded from numba's cache)
        start = time.perf_counter()
        for w in omegas:
            module.frc(w, 1.0)
        emitted = time.perf_counter() - start
        nodes = "+".join(str(int(k)) for k in module.PIECES[:, 3])
        error = module.INTERPOLATION_ERROR
    print(f"the emitted module's frc(w, 1), 500 frequencies: {emitted * 1e3:.0f} ms (its forced "
          f"terms on {nodes} Chebyshev nodes, interpolation error {error:.1e})")
    full, _, out = timed([*LINDSTEDT, "response", PAIR, "--param", "f=1/100", "--omega",
                          "0.95:1.05", "--json"])
    data = json.loads(out)
    peak = max(max(b["amplitudes"]["x1"]) for b in data["branches"])
    first = _first_harmonic(model, response, omegas)
    print(f"response PAIR (full-order balance, every branch) over the same range: {full:.1f} s "
          f"wall; its peak first-harmonic amplitude of x1 {peak:.7f}, the SSM's on the same "
          f"grid {first:.7f} (relative {abs(first / peak - 1):.1e})")
    reduced, _, _ = timed([*LINDSTEDT, "ssm", PAIR, "--param", "f=1/100", "--order", "11",
                           "--omega", "0.95:1.05:500", "--json"])
    print(f"ssm PAIR --order 11 --omega 0.95:1.05:500 --json: {reduced:.2f} s wall: "
          f"{full / reduced:.0f}× faster as commands, "
          f"{full / np.median(runs):.0f}× in process")


def _first_harmonic(model, response, omegas) -> float:
    """The largest first-harmonic amplitude of x1 over the SSM's steady states (the balance's
    measure), from the same terms as the steady states' amplitudes."""
    from lindstedt.analysis.ssm_forced import forcing_table

    table = {f.omega: f for f in forcing_table(model, omegas, np.arange(2))}
    best = 0.0
    K = model.order
    for s in response.states:
        c = model.harmonics(np.array([s.rho]), np.arange(2), np.array([s.psi]))[0]
        for k, X in enumerate(table[s.omega].X):
            for r in range(k + 1):
                if k - 2 * r + 1 == 1:
                    c[K + 1] += s.rho**k * X[r] * np.exp(1j * (k - 2 * r) * s.psi)
        best = max(best, 2 * abs(c[K + 1, 0]))
    return best


ACCURACY = [
    ("a cubic pair, ζ = 0.005",
     "x1'' + 0.01*x1' + 2*x1 - x2 + x1**3 = f*cos(w*t); x2'' + 0.01*x2' + 2*x2 - x1 = 0",
     "1/100", 0.95, 1.1),
    ("quadratic and cubic, ζ = 0.05",
     "x1'' + 0.1*x1' + 2*x1 - x2 + 0.5*x1**2 + x1**3 = f*cos(w*t); "
     "x2'' + 0.1*x2' + 2*x2 - x1 + 0.3*x2**2 = 0", "1/10", 0.85, 1.15),
    ("a quadratic pair, ζ = 0.02, driven hard",
     "x1'' + 0.04*x1' + 2*x1 - x2 + 0.6*x1**2 = f*cos(w*t); x2'' + 0.04*x2' + 2*x2 - x1 = 0",
     "1/20", 0.8, 1.1),
]


def part_accuracy() -> None:
    print("## 4. the forced peak against full-order shooting, by order K")
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from lindstedt.analysis.ssm import ssm
    from lindstedt.analysis.ssm_forced import forced_response
    from lindstedt.derive.system import parse_system
    from ssm_reference import peak as shot_peak
    from ssm_reference import terms_force

    for title, text, f, lo, hi in ACCURACY:
        system = parse_system(text, {"f": f}, driven=True)
        w = system.matrices
        t = w.force
        terms = [(int(e), [int(k) for k in fa if k >= 0], float(c))
                 for e, fa, c in zip(t.equation, t.factors, t.coefficient, strict=True)]
        omega, amplitude = shot_peak(w.mass.toarray(), w.damping.toarray(),
                                     w.stiffness.toarray(), terms_force(2, terms), w.drive,
                                     lo, hi, 0)
        shift = omega / abs(ssm(system, 1, 1).lam) - 1
        row = []
        for order in (3, 5, 7, 9, 11):
            top = forced_response(ssm(system, 1, order), np.linspace(lo, hi, 200),
                                  np.arange(2)).peaks[0]
            row.append(f"K={order}: {abs(top.amplitude / amplitude - 1):.1e}")
        print(f"{title} (f = {f}; shot peak {amplitude:.9f} at omega = {omega:.6f}, "
              f"{shift:+.1%} from the linear frequency): " + ", ".join(row))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="without the 10⁵-mass chain")
    args = parser.parse_args()
    os.environ.setdefault("PYTHONHASHSEED", "0")
    part_pair()
    part_chains([(1000, 7, True), (10_000, 5, True)]
                + ([] if args.quick else [(100_000, 5, False)]))
    part_response()
    part_accuracy()


if __name__ == "__main__":
    main()
