"""Speed against accuracy for the driven amplitudes A_n(ω) and the response r(ω).

    .venv/bin/python benchmarks/driven_speed_accuracy.py

Writes docs/figures/driven_speed_accuracy.png (measured costs: `make demo` draws its own copy
into out/) and prints, per quantity and ω, the Pareto front: method, order, µs per ω, error.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from generator.charts import DRIVEN_CHART_OMEGA, driven_speed_accuracy_figure
from generator.choose import DRIVEN_QUANTITIES, driven_tradeoffs, driven_truth, pareto_front


def main() -> None:
    print(f"wrote {driven_speed_accuracy_figure(Path('docs/figures/driven_speed_accuracy.png'))}")
    truth = driven_truth(0.1, 1.0, np.inf, np.array(DRIVEN_CHART_OMEGA))
    data = driven_tradeoffs(truth, 0.1, 1.0, np.inf)
    cost = np.array([t.ns_per_point for t in data]) / 1e3
    for quantity in DRIVEN_QUANTITIES:
        for k, w in enumerate(DRIVEN_CHART_OMEGA):
            err = np.array([t.errors[quantity][k] for t in data])
            front = pareto_front(cost, err)
            print(f"{quantity} at ω = {w:g}: " + ", ".join(
                f"{data[i].method} {data[i].order} ({cost[i]:.1f} µs, {err[i]:.0e})"
                for i in front))


if __name__ == "__main__":
    main()
