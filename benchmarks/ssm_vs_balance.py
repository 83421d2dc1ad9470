"""A 500-point forced response from the reduced model (``ssm``, ``generate --ssm``) against the
full-order harmonic balance (``response SYSTEM``) on chains of n masses, all in the same run.

    .venv/bin/python benchmarks/ssm_vs_balance.py            # n = 2, 3, 4, 5, 6, 8 (~6 minutes)
    .venv/bin/python benchmarks/ssm_vs_balance.py --quick    # n = 2 only
    .venv/bin/python benchmarks/ssm_vs_balance.py --large    # and n = 12 (~5 minutes more)
    .venv/bin/python benchmarks/ssm_vs_balance.py --sizes 12  # these sizes only

The issue's target: a 500-point forced response curve from the reduced model in ≤ 0.5 s in
process, and ≥ 100× faster than ``response SYSTEM`` on the largest system that one handles, at
1e-3 relative agreement near the peak.

**The systems.**  A chain of n unit masses between two walls, spring j (j = 0 … n) joining
x_j and x_(j+1) with stiffness k_j = 1 + 3 (j/n)² (graded: ω₂/ω₁ = 1.84 … 1.90, ω₃/ω₁ = 2.62 …
2.75, away from 1:3), mass-proportional damping c x_i' with c = 2·0.01·ω₁ (ζ₁ = 0.01, the
higher modes lighter), a cubic spring 4 x₁³ on the first mass to the wall, the drive
f cos(ωt), f = 1/100, on the first mass: the peak moves 1.3 % (n = 5) to 2.7 % (n = 3) above
ω₁.  Written as text (``response`` reads no model folder), the same text for both commands.
Both over ω ∈ [0.9 ω₁, 1.1 ω₁] (the bounds printed to 6 digits, passed as ``--omega A:B``).

**What is timed** (2 shared cores; one thing at a time):

- ``response SYSTEM --param f=1/100 --omega A:B --json`` as a user meets it: the command's
  wall time, start-up and output included, at its default ``--harmonics`` (8), one run.  Its
  cost estimate refuses a run estimated past 60 s: where it does, the refusal (and its time)
  is printed, and the run is repeated with ``--allow-slow`` (marked ``*``).
- (a) the reduction in process, ``analysis.ssm.ssm(system, 1, K)`` (the system parsed
  before, not timed), median of 3;
- (b) the 500-point forced response in process, ``analysis.ssm_forced.forced_response`` on
  ``linspace(A, B, 500)``, every coordinate an output (``ssm``'s default up to 12), the
  reduction excluded, median of 3;
- (c) the emitted module's ``frc(w, 1)`` called on the same 500 frequencies (``generate
  SYSTEM --ssm 1 --order K --omega A:B``, then imported): the first call compiles (numba;
  excluded from (c), printed apart, as is ``generate``'s wall time), median of 3 loops;
- ``ssm SYSTEM --mode 1 --order K --omega A:B --json`` as a command, the whole SSM route
  ((a) + (b) with start-up, SymPy's parse, the backbone and the output), median of 3.

Ratios: ``response``'s wall time over (b), over (c) and over the ``ssm`` command.

**Agreement.**  ``response`` reports each coordinate's first-harmonic amplitude; the SSM's
first harmonic of x₁ is computed from the same terms as its steady states' amplitudes (the
autonomous SSM's harmonics at (ρ, ψ) and the first-order forced terms).  Printed: the
balance's peak (the largest of its traced points: the continuation's step; and refined by
the parabola in ω through that point and the two beside it), the SSM's peak (on 2 001
frequencies within ±0.3 % of its refined peak) at orders K and K + 2 (converged where they
agree), the peaks' and the upper folds' ω; and, at each of the balance's points within 5 %
below its peak, the relative difference from the SSM's state at the same ω (the nearest in
amplitude) and the distance to the SSM's curve in (Δω/ω, ΔA/A), the largest of each: on a
flank as steep as a resonance's (ζ = 0.01) the first is the curves' small shift in ω
magnified by (ω/A)dA/dω, tens; the second is not.  Points past the SSM's upper fold are
left out (its upper state has jumped there) and counted; the folds' ω are compared instead.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

LINDSTEDT = [sys.executable, "-m", "lindstedt"]
FORCE = "1/100"
CUBIC = 4
ZETA = 0.01
SPAN = 0.1
POINTS = 500
ORDER = 9
CHECK_ORDER = 11
NEAR_PEAK = 0.05
SIZES = (2, 3, 4, 5, 6, 8)
LARGE = 12


def chain(n: int) -> tuple[str, float]:
    """The chain of ``n`` masses as a SYSTEM text, and its lowest linear frequency ω₁."""
    k = [1 + 3 * Fraction(j * j, n * n) for j in range(n + 1)]
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] = k[i] + k[i + 1]
        if i + 1 < n:
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    w1 = float(np.sqrt(np.linalg.eigvalsh(K)[0]))
    c = Fraction(round(2 * ZETA * w1 * 10**5), 10**5)
    equations = []
    for i in range(n):
        terms = [f"x{i + 1}'' + {c}*x{i + 1}' + {k[i] + k[i + 1]}*x{i + 1}"]
        if i > 0:
            terms.append(f"- {k[i]}*x{i}")
        if i + 1 < n:
            terms.append(f"- {k[i + 1]}*x{i + 2}")
        if i == 0:
            terms.append(f"+ {CUBIC}*x1**3")
        equations.append(" ".join(terms) + (" = f*cos(w*t)" if i == 0 else " = 0"))
    return "; ".join(equations), w1


def run(args: list[str]) -> tuple[float, subprocess.CompletedProcess]:
    """Wall seconds and the finished process of one command (output captured)."""
    start = time.perf_counter()
    done = subprocess.run(args, capture_output=True, text=True)
    return time.perf_counter() - start, done


def median_time(call, runs: int = 3) -> float:
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def first_harmonics(model, omegas: np.ndarray) -> list[tuple[float, float]]:
    """Every steady state's (ω, first-harmonic amplitude of x₁) at ``omegas`` (ascending)."""
    from lindstedt.analysis.ssm_forced import forced_response, forcing_table

    out = np.array([0])
    response = forced_response(model, omegas, out)
    table = {f.omega: f for f in forcing_table(model, omegas, out)}
    if not response.states:
        return []
    K = model.order
    rho = np.array([s.rho for s in response.states])
    psi = np.array([s.psi for s in response.states])
    c = model.harmonics(rho, out, psi)  # (states, 2K + 1, outputs): harmonic h at K + h
    for i, s in enumerate(response.states):
        for k, X in enumerate(table[s.omega].X):
            if k % 2 == 0:  # row k/2: p₁^(k/2) p₂^(k/2) e^{iΩt}, harmonic 1
                c[i, K + 1] += s.rho**k * X[k // 2]
    return [(s.omega, float(2 * abs(c[i, K + 1, 0]))) for i, s in enumerate(response.states)]


def ssm_peak(model, lo: float, hi: float) -> tuple[float, float]:
    """The SSM's first-harmonic peak of x₁ (amplitude, ω): its refined peak's ω from
    ``forced_response`` over [lo, hi], then 2 001 frequencies within ±0.3 % of it."""
    from lindstedt.analysis.ssm_forced import forced_response

    top = forced_response(model, np.linspace(lo, hi, POINTS), np.array([0])).peaks[0]
    states = first_harmonics(model, np.linspace(top.omega * 0.997, top.omega * 1.003, 2001))
    omega, amplitude = max(states, key=lambda s: s[1])
    return amplitude, omega


def refined(branches: list[dict]) -> tuple[float, float]:
    """The balance's peak of x₁ (amplitude, ω): the parabola in ω through its largest traced
    point and the two beside it on the same branch (where they are monotone in ω), else that
    point."""
    a, i, b = max((a, i, b) for b in branches for i, a in enumerate(b["amplitudes"]["x1"]))
    branch = next(x for x in branches if x is b)
    w, r = branch["omega"], branch["amplitudes"]["x1"]
    if 0 < i < len(w) - 1 and (w[i - 1] - w[i]) * (w[i] - w[i + 1]) > 0:
        c2, c1, c0 = np.polyfit(w[i - 1:i + 2], r[i - 1:i + 2], 2)
        top = -c1 / (2 * c2)
        if min(w[i - 1], w[i + 1]) < top < max(w[i - 1], w[i + 1]):
            return float(c0 - c1 * c1 / (4 * c2)), float(top)
    return a, w[i]


def near_peak(model, branches: list[dict], peak: float, fold: float
              ) -> tuple[float, float, int, int]:
    """How far the balance's points within :data:`NEAR_PEAK` below its peak lie from the
    SSM's curve: the largest relative difference from the SSM's first harmonic of x₁ at the
    same ω (its state nearest in amplitude; on a flank as steep as a resonance's this is the
    ω error times (ω/A)dA/dω), and the largest distance to the SSM's curve in
    (Δω/ω, ΔA/A) (the curve on 8 001 frequencies over the points' range ±0.3 %); how many
    points, and how many more past the SSM's upper fold ``fold`` (left out: the SSM's upper
    state has jumped there; the folds' ω are compared instead)."""
    every = sorted({(w, a) for b in branches
                    for w, a in zip(b["omega"], b["amplitudes"]["x1"], strict=True)
                    if a >= (1 - NEAR_PEAK) * peak})
    near = [(w, a) for w, a in every if w <= fold]
    if not near:
        return np.nan, np.nan, 0, len(every)
    omegas = np.array(sorted({w for w, _ in near}))
    same = first_harmonics(model, omegas)
    dense = np.array(first_harmonics(model, np.linspace(omegas[0] * 0.997, omegas[-1] * 1.003,
                                                        8001)))
    vertical = distance = 0.0
    for w, a in near:
        here = [s for om, s in same if om == w]
        vertical = max(vertical, min(abs(s / a - 1) for s in here) if here else np.inf)
        distance = max(distance, float(np.min(np.hypot(dense[:, 0] / w - 1,
                                                       dense[:, 1] / a - 1))))
    return vertical, distance, len(near), len(every) - len(near)


def estimate(text: str, lo: float, hi: float) -> float:
    """``response``'s own cost estimate (costs.response_cost) of the run, seconds."""
    from lindstedt.costs import response_cost

    args = argparse.Namespace(model=text, param=[f"f={FORCE}"], name=None, harmonics=8,
                              omega_min=lo, omega_max=hi, eps=None, force=None, Q=None)
    return response_cost(args).seconds


def emitted(text: str, span: str, omegas: np.ndarray) -> tuple[float, float, float, float]:
    """``generate --ssm 1``'s wall time, the module's import and first call (compile), the
    500 calls of ``frc(w, 1)`` (median of 3), and the largest max|x₁| of its states."""
    with tempfile.TemporaryDirectory() as tmp:
        made, done = run([*LINDSTEDT, "generate", text, "--param", f"f={FORCE}", "--ssm", "1",
                          "--order", str(ORDER), "--omega", span, "--out", tmp])
        if done.returncode:
            raise RuntimeError(done.stderr)
        start = time.perf_counter()
        spec = importlib.util.spec_from_file_location("ssm1", Path(tmp) / "ssm1.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        module.frc(float(omegas[0]), 1.0)
        compiled = time.perf_counter() - start

        def loop() -> None:
            for w in omegas:
                module.frc(w, 1.0)

        calls = median_time(loop)
        top = max(float(np.nanmax(module.frc(w, 1.0)[1][:, 0], initial=0.0)) for w in omegas)
        sys.modules.pop("ssm1", None)
    return made, compiled, calls, top


def one_size(n: int) -> dict:
    from lindstedt.analysis.ssm import ssm
    from lindstedt.analysis.ssm_forced import forced_response
    from lindstedt.derive.system import parse_system

    text, w1 = chain(n)
    lo, hi = float(f"{(1 - SPAN) * w1:.6g}"), float(f"{(1 + SPAN) * w1:.6g}")
    span = f"{lo!r}:{hi!r}"
    omegas = np.linspace(lo, hi, POINTS)
    row: dict = {"n": n, "w1": w1, "span": span, "estimate": estimate(text, lo, hi)}

    # the full-order balance, as a user meets it
    command = [*LINDSTEDT, "response", text, "--param", f"f={FORCE}", "--omega", span, "--json"]
    seconds, done = run(command)
    row["slow"] = False
    if done.returncode:
        row["refused"] = (seconds, done.stderr.strip().splitlines()[-1])
        seconds, done = run([*command, "--allow-slow"])
        row["slow"] = True
        if done.returncode:
            raise RuntimeError(done.stderr)
    row["response"] = seconds
    data = json.loads(done.stdout)
    branches = data["branches"]
    row["points"] = sum(len(b["omega"]) for b in branches)
    row["balance_peak"] = max(max(b["amplitudes"]["x1"]) for b in branches)

    # the SSM route
    system = parse_system(text, {"f": FORCE}, driven=True)
    outputs = np.arange(n)
    row["reduce"] = median_time(lambda: ssm(system, 1, ORDER))
    model = ssm(system, 1, ORDER)
    row["frc"] = median_time(lambda: forced_response(model, omegas, outputs))
    response = forced_response(model, omegas, outputs)
    row["frc_top"] = max(s.amplitude[0] for s in response.states)
    row["near"] = len(model.near)
    row["generate"], row["compile"], row["emitted"], row["emitted_top"] = emitted(
        text, span, omegas)
    whole = [*LINDSTEDT, "ssm", text, "--param", f"f={FORCE}", "--mode", "1", "--order",
             str(ORDER), "--omega", span, "--json"]
    times = []
    for _ in range(3):
        seconds, done = run(whole)
        if done.returncode:
            raise RuntimeError(done.stderr)
        times.append(seconds)
    row["command"] = float(np.median(times))

    # agreement
    row["ssm_peak"], row["ssm_peak_omega"] = ssm_peak(model, lo, hi)
    row["check_peak"], _ = ssm_peak(ssm(system, 1, CHECK_ORDER), lo, hi)
    row["refined"], row["refined_omega"] = refined(branches)
    # the upper folds: the first above each peak (the jump down of a hardening curve)
    row["ssm_fold"] = min((w for w, _ in response.folds if w >= row["ssm_peak_omega"]),
                          default=np.inf)
    row["balance_fold"] = min((w for w in data["folds"] if w >= row["refined_omega"]),
                              default=np.inf)
    row["vertical"], row["distance"], row["near_points"], row["past_fold"] = near_peak(
        model, branches, row["balance_peak"], row["ssm_fold"])
    return row


def report(rows: list[dict]) -> None:
    print("## the systems and the balance")
    for r in rows:
        refused = ""
        if "refused" in r:
            refused = (f"; refused without --allow-slow in {r['refused'][0]:.1f} s: "
                       f"\"{r['refused'][1]}\"")
        print(f"n = {r['n']}: omega1 = {r['w1']:.6f}, --omega {r['span']}; response's cost "
              f"estimate {r['estimate']:.0f} s, measured {r['response']:.1f} s"
              f"{' (--allow-slow)' if r['slow'] else ''}, {r['points']} points traced"
              f"{refused}; the SSM's near resonances reported: {r['near']}")
    print()
    print("## times (s; response and ssm as commands, wall; (a), (b), (c) in process)")
    print(f"{'n':>3} {'response':>9} {'(a) reduce':>10} {'(b) frc':>8} {'(c) emit':>8} "
          f"{'ssm cmd':>7} {'resp/(b)':>8} {'resp/(c)':>8} {'resp/cmd':>8} "
          f"{'generate':>8} {'compile':>7}")
    for r in rows:
        mark = "*" if r["slow"] else " "
        print(f"{r['n']:>3} {r['response']:>8.2f}{mark} {r['reduce']:>10.4f} {r['frc']:>8.3f} "
              f"{r['emitted']:>8.4f} {r['command']:>7.2f} {r['response'] / r['frc']:>8.0f} "
              f"{r['response'] / r['emitted']:>8.0f} {r['response'] / r['command']:>8.1f} "
              f"{r['generate']:>8.2f} {r['compile']:>7.2f}")
    print("(* with --allow-slow: the cost estimate refused the run; compile: the emitted "
          "module's import and first call, numba, excluded from (c))")
    print()
    print(f"## agreement: first-harmonic amplitude of x1 at the peak; K = {ORDER}, check "
          f"K = {CHECK_ORDER}")
    print(f"{'n':>3} {'balance pts':>11} {'refined':>10} {'SSM K':>10} {'rel':>7} "
          f"{'SSM K+2':>10} {'K:K+2':>7} {'w peak':>7} {'w rel':>7} {'fold rel':>8} "
          f"{'same w':>7} {'dist':>7} {'pts':>5} {'max|x1| (b)':>11} {'(c)':>10}")
    for r in rows:
        print(f"{r['n']:>3} {r['balance_peak']:>11.8f} {r['refined']:>10.8f} "
              f"{r['ssm_peak']:>10.8f} {abs(r['ssm_peak'] / r['refined'] - 1):>7.1e} "
              f"{r['check_peak']:>10.8f} {abs(r['ssm_peak'] / r['check_peak'] - 1):>7.1e} "
              f"{r['ssm_peak_omega'] / r['w1'] - 1:>+7.4f} "
              f"{abs(r['ssm_peak_omega'] / r['refined_omega'] - 1):>7.1e} "
              f"{_fold(r['ssm_fold'], r['balance_fold']):>8} {r['vertical']:>7.1e} "
              f"{r['distance']:>7.1e} {r['near_points']:>3}+{r['past_fold']} {r['frc_top']:>11.8f} "
              f"{r['emitted_top']:>10.8f}")
    print("(balance pts: the largest of its traced points; refined: the parabola in omega "
          "through it and its neighbours; rel: the SSM's peak at K against the refined one; "
          "K:K+2: the SSM's peaks at K and K + 2; w peak: the SSM's peak's omega over "
          "omega1 - 1; w rel: the peaks' omega, SSM against the refined balance; fold rel: "
          "the upper folds' omega; same w: the largest relative difference at the balance's "
          f"points within {NEAR_PEAK:.0%} below its peak from the SSM at the same omega, dist: "
          "their largest distance to the SSM's curve in (dw/w, dA/A), pts: how many + how "
          "many more past the SSM's upper fold, left out; "
          "max|x1|: the largest state on the 500-point grid, in process (b) and from the "
          "emitted module (c))")


def _fold(ssm: float, balance: float) -> str:
    """The folds' relative difference; "none" where neither has one, "one" where one has."""
    if np.isinf(ssm) and np.isinf(balance):
        return "none"
    if np.isinf(ssm) or np.isinf(balance):
        return "one"
    return f"{abs(ssm / balance - 1):.1e}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n = 2 only")
    parser.add_argument("--large", action="store_true",
                        help=f"also n = {LARGE} (response SYSTEM alone runs about 5 minutes)")
    parser.add_argument("--sizes", type=lambda t: tuple(int(x) for x in t.split(",")),
                        help="these chain sizes instead, e.g. 12 or 2,5")
    args = parser.parse_args()
    rows = []
    sizes = (2,) if args.quick else SIZES + ((LARGE,) if args.large else ())
    for n in args.sizes or sizes:
        try:
            rows.append(one_size(n))
        except Exception as error:  # one size's failure is reported, the others kept
            print(f"n = {n} failed: {error!r}", flush=True)
            continue
        print(f"n = {n} done", file=sys.stderr, flush=True)
    report(rows)


if __name__ == "__main__":
    main()
