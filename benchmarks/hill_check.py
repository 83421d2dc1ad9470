"""The notes' claim on the 1/3 subharmonic, checked on a grid (a report, not a timing).

    .venv/bin/python benchmarks/hill_check.py

For every (ε, ω, f) of the grid where eq. 10.87 has real roots, compare the Hill-equation
verdict (linearised about q₀) and the full Hill equation's (linearised about the whole orbit
q(t) of the harmonic balance, no shooting) with the Floquet multipliers of the true orbit found
by shooting.  Then the driven Duffing branches (eq. 10.60 with damping): the Hill equation about
the balance orbit cut to its first harmonic (the notes' q₀), about the whole balance orbit, and
shooting, on a grid of (ε, f, Q, ω).
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from lindstedt.analysis.driven import Drive, amplitudes
from lindstedt.analysis.periodic import periodic_orbits
from lindstedt.analysis.subharmonic import subharmonic
from lindstedt.numerics.floquet import multipliers_stable, orbit_hill_multipliers


def _verdict(stable: bool | None, name: str, missing: str) -> str:
    return missing if stable is None else f"{name} {'stable' if stable else 'unstable'}"


def driven() -> None:
    """The driven branches' verdicts: q₀ (first harmonic) Hill, full Hill, shooting."""
    counts: Counter = Counter()
    wrong = []
    for eps in (0.1, 0.3, -0.05):
        for force in (0.3, 1.0):
            for Q in (10.0, 50.0):
                for omega in np.linspace(0.6, 2.0, 8):
                    d = Drive(eps, force, float(omega), Q)
                    terms = {(1, 0): 1.0, (3, 0): eps, (0, 1): d.damping}
                    for o in periodic_orbits(d, 8).orbits:
                        if o.orbit is None or o.balance is None:
                            counts["no balance or no true orbit"] += 1
                            continue
                        A, B = amplitudes(o.balance.coefficients, 0.0, 15)
                        full = multipliers_stable(orbit_hill_multipliers(terms, A, B, d.omega),
                                                  True)
                        cut = multipliers_stable(orbit_hill_multipliers(
                            terms, {1: A[1]}, {1: B[1]}, d.omega), True)
                        counts[", ".join(_verdict(v, n, "") for v, n in (
                            (cut, "q0 Hill"), (full, "full"), (o.orbit.stable, "true")))] += 1
                        if cut != o.orbit.stable:
                            wrong.append(f"eps {eps}, f {force}, Q {Q:g}, omega {omega:.2f}, "
                                         f"r {o.r:.3f}")
    print(f"\ndriven Duffing branches\n{'verdicts (q0 Hill, full Hill, shooting)':<56} "
          f"{'cases':>6}")
    for verdict, n in sorted(counts.items()):
        print(f"{verdict:<56} {n:>6}")
    print("q0 Hill wrong at: " + "; ".join(wrong))


def main() -> None:
    counts: Counter = Counter()
    gap, margin = 0.0, np.inf
    for eps in (0.05, 0.1, 0.3, 1.0):
        for omega in np.linspace(1.02, 2.0, 8):
            for force in (0.1, 0.5, 1.0, 3.0, 10.0):
                _, _, solutions = subharmonic(eps, force, float(omega))
                for s in solutions:
                    hill = "Hill stable" if s.hill_stable else "Hill unstable"
                    full = _verdict(s.full_hill_stable, "full", "no balance")
                    true = _verdict(None if s.orbit is None else s.orbit.stable, "true",
                                    "no true orbit")
                    counts[(s.root, f"{hill}, {full}, {true}")] += 1
                    if s.orbit is not None and s.full_hill_multipliers is not None:
                        lam, mu = (np.sort_complex(m) for m in
                                   (s.full_hill_multipliers, s.orbit.multipliers))
                        gap = max(gap, float(np.max(np.abs(lam - mu))))
                        margin = min(margin, abs(abs(np.sum(mu).real) - 2))
    print(f"{'root':<5} {'verdicts (q0 Hill, full Hill, shooting)':<50} {'cases':>6}")
    for (root, verdict), n in sorted(counts.items()):
        print(f"{root:<5} {verdict:<50} {n:>6}")
    print(f"\nfull Hill vs shooting: largest multiplier difference {gap:.1e}; the closest "
          f"shot orbit to the stability boundary has ||tr M| - 2| = {margin:.1e}")
    driven()


if __name__ == "__main__":
    main()
