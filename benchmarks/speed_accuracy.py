"""Speed against accuracy of every period method: the chart the README shows.

    .venv/bin/python benchmarks/speed_accuracy.py

Writes docs/figures/speed_accuracy.png (measured costs: it changes from run to run, which is why
`make demo` draws its own copy into out/ instead) and prints the Pareto front at each x.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lindstedt.charts import CHART_X, speed_accuracy_figure
from lindstedt.choose import pareto_front, tradeoffs


def main() -> None:
    path = speed_accuracy_figure(Path("docs/figures/speed_accuracy.png"))
    print(f"wrote {path}")
    data = tradeoffs(np.array(CHART_X))
    cost = np.array([t.ns_per_point for t in data])
    for k, x in enumerate(CHART_X):
        err = np.array([t.errors[k] for t in data])
        front = pareto_front(cost, err)
        print(f"x = {x:g}: " + ", ".join(f"{data[i].method} {data[i].order} "
                                         f"({cost[i]:.2f} ns, {err[i]:.0e})" for i in front))


if __name__ == "__main__":
    main()
