"""Where the suite's time goes: each layer of ``make test`` run as the Makefile runs it (every
core, pytest-xdist), its wall time and its CPU time (user + system of pytest and every process
it waited for: workers, commands, compilers), the test files whose tests take longest together,
and the ten slowest tests of the whole suite (their own wall time from pytest's JUnit report,
setup included).  On a machine shared with other work, compare CPU times: wall times follow
the load.

    python benchmarks/suite_times.py [--top 10] [PYTEST_ARGS...]

docs/benchmarks.md records its output next to the budget (``make test`` ≤ 10 minutes on a
fresh 2-core machine, the install included)."""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAYERS = ("exact", "printers or emitted")
# NOTE: the Makefile's two pytest runs, in its order: the exact layer first and alone.


def _children_cpu() -> float:
    """CPU seconds (user + system) of every finished process this one waited for."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def run_layer(marker: str, report: Path, extra: list[str]) -> tuple[float, float, int]:
    """One layer as ``make test`` runs it: its wall time, its CPU time and pytest's exit
    code."""
    start, cpu = time.perf_counter(), _children_cpu()
    done = subprocess.run([sys.executable, "-m", "pytest", "-n", "auto", "--dist", "worksteal",
                           "-m", marker, "-q", f"--junitxml={report}", *extra], cwd=ROOT,
                          check=False)
    return time.perf_counter() - start, _children_cpu() - cpu, done.returncode


def test_times(report: Path) -> list[tuple[float, str]]:
    """Each test case's time in a JUnit report, with its name."""
    return [(float(case.get("time", 0.0)), f"{case.get('classname')}::{case.get('name')}")
            for case in ET.parse(report).iter("testcase")]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--top", type=int, default=10, help="how many slowest tests to list")
    args, extra = parser.parse_known_args()
    rows, cases, failed = [], [], False
    with tempfile.TemporaryDirectory() as tmp:
        for i, marker in enumerate(LAYERS):
            report = Path(tmp) / f"layer{i}.xml"
            wall, cpu, code = run_layer(marker, report, extra)
            times = test_times(report)
            rows.append((marker, wall, cpu, len(times), sum(t for t, _ in times)))
            cases += times
            failed |= code != 0
    print(f"\n{'layer':<22} {'wall':>9} {'cpu':>9} {'tests':>6} {'summed':>9}")
    for marker, wall, cpu, count, summed in rows:
        print(f"{marker:<22} {wall:>8.1f}s {cpu:>8.1f}s {count:>6} {summed:>8.1f}s")
    print(f"{'both':<22} {sum(r[1] for r in rows):>8.1f}s {sum(r[2] for r in rows):>8.1f}s "
          f"{sum(r[3] for r in rows):>6}")
    files: dict[str, float] = {}
    for seconds, name in cases:
        files[name.split("::")[0]] = files.get(name.split("::")[0], 0.0) + seconds
    print(f"\nthe {args.top} test files whose tests take longest together:")
    for name, seconds in sorted(files.items(), key=lambda f: -f[1])[:args.top]:
        print(f"{seconds:>8.1f}s  {name}")
    print(f"\nthe {args.top} slowest tests:")
    for seconds, name in sorted(cases, reverse=True)[:args.top]:
        print(f"{seconds:>8.1f}s  {name}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
