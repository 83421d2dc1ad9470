"""Speed against accuracy for the driven amplitudes A_n(ω) and the response r(ω).

    .venv/bin/python benchmarks/driven_speed_accuracy.py

Besides the methods `choose amplitudes|response` weighs (NumPy code, timed per ω), the
emitted modules at a few orders (`choose.emitted_driven`: `generate driven`, the exact
undamped μ-expansion as compiled ufuncs; `generate balance`, compiled Newton).  Writes
docs/figures/driven_speed_accuracy.png (measured costs: `make demo` draws its own copy,
without the emitted points, into out/) and prints, per quantity and ω, the Pareto front:
method, order, µs per ω, error.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lindstedt.charts import DRIVEN_CHART_OMEGA, driven_speed_accuracy_figure
from lindstedt.choose import (
    DRIVEN_QUANTITIES,
    driven_tradeoffs,
    driven_truth,
    emitted_driven,
    pareto_front,
)

EPS, FORCE = 0.1, 1.0
EMITTED = [("mu_expansion", k) for k in (1, 2, 3)] + [("harmonic_balance", n)
                                                      for n in (2, 3, 4, 6)]


def main() -> None:
    truth = driven_truth(EPS, FORCE, np.inf, np.array(DRIVEN_CHART_OMEGA))
    extra = [emitted_driven(m, k, truth, EPS, FORCE, np.inf) for m, k in EMITTED]
    path = driven_speed_accuracy_figure(Path("docs/figures/driven_speed_accuracy.png"),
                                        extra=extra)
    print(f"wrote {path}")
    data = driven_tradeoffs(truth, EPS, FORCE, np.inf) + extra
    cost = np.array([t.ns_per_point for t in data]) / 1e3
    for quantity in DRIVEN_QUANTITIES:
        for k, w in enumerate(DRIVEN_CHART_OMEGA):
            err = np.array([t.errors[quantity][k] for t in data])
            front = pareto_front(cost, err)
            print(f"{quantity} at ω = {w:g}: " + ", ".join(
                f"{data[i].method} {data[i].order} ({cost[i]:.3g} µs, {err[i]:.0e})"
                for i in front))
    print("\nemitted modules (µs per ω; max error over the four ω, amplitudes / response):")
    for t in extra:
        print(f"  {t.method} {t.order}: {t.ns_per_point / 1e3:.3g} µs, "
              f"{np.max(t.errors['amplitudes']):.1e} / {np.max(t.errors['response']):.1e}")


if __name__ == "__main__":
    main()
