"""The cores a local sweep may use: light (``os`` only), so that the command line's parser
bounds ``--workers`` without importing NumPy."""

from __future__ import annotations

import os


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity, a container's cpuset): the most
    single-threaded workers a local sweep keeps busy; more only share them.

    >>> 1 <= usable_cores() <= (os.cpu_count() or 1)
    True
    """
    count = getattr(os, "process_cpu_count", None)  # Python 3.13: the affinity, portably
    if count is not None:
        return count() or 1
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0)) or 1
    return os.cpu_count() or 1
