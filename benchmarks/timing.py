"""The one timing rule of every benchmark script: best wall time of ``repeat`` runs."""

from __future__ import annotations

import time
from collections.abc import Callable


def best(fn: Callable[[], object], repeat: int = 3) -> float:
    """Minimum over ``repeat`` calls of ``fn``: the least disturbed measurement."""
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out)


def median(fn: Callable[[], object], repeat: int = 5) -> float:
    """Median over ``repeat`` calls of ``fn``: the typical time on a shared machine."""
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return sorted(out)[len(out) // 2]
