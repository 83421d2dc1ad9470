"""The notes' claim on the 1/3 subharmonic, checked on a grid (a report, not a timing).

    .venv/bin/python benchmarks/hill_check.py

For every (ε, ω, f) of the grid where eq. 10.87 has real roots, compare the Hill-equation
verdict (linearised about q₀) with the Floquet multipliers of the true orbit found by shooting.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
from lindstedt.response import subharmonic


def main() -> None:
    counts: Counter = Counter()
    for eps in (0.05, 0.1, 0.3, 1.0):
        for omega in np.linspace(1.02, 2.0, 8):
            for force in (0.1, 0.5, 1.0, 3.0, 10.0):
                _, _, solutions = subharmonic(eps, force, float(omega))
                for s in solutions:
                    if s.orbit is None:
                        counts[(s.root, "no true orbit found from this root")] += 1
                    else:
                        hill = "Hill stable" if s.hill_stable else "Hill unstable"
                        true = "true stable" if s.orbit.stable else "true unstable"
                        counts[(s.root, f"{hill}, {true}")] += 1
    print(f"{'root':<5} {'verdicts':<38} {'cases':>6}")
    for (root, verdict), n in sorted(counts.items()):
        print(f"{root:<5} {verdict:<38} {n:>6}")


if __name__ == "__main__":
    main()
