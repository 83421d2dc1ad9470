"""Where the suite's time goes, as make test runs it.

``make test``'s pytest run (every core, pytest-xdist, whole files handed out longest first):
its wall time and its CPU time (user + system of pytest and every process it waited for:
workers, commands, compilers); each layer's test count and summed test time, the test files
whose tests take longest together, and the ten slowest tests (their own wall time from pytest's
JUnit report, setup included).  On a machine shared with other
work, compare CPU times: wall times follow the load.

    python benchmarks/suite_times.py [--top 10] [--write-durations] [PYTEST_ARGS...]

``--write-durations`` writes each file's summed seconds to tests/durations.json, the order in
which the run hands files out (tests/conftest.py): refresh it when files grow or move.
docs/benchmarks.md records the output next to the budget (``make test`` ≤ 10 minutes on a
fresh 2-core machine, the install included)."""

from __future__ import annotations

import argparse
import json
import re
import resource
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SUITE = re.search(r"^SUITE = (.*)$", (ROOT / "Makefile").read_text(), re.M).group(1).split()
# NOTE: the Makefile's own pytest options, so that this run is make test's.
sys.path.insert(0, str(ROOT / "tests"))
from conftest import DURATIONS, LAYER_OF  # noqa: E402


def _children_cpu() -> float:
    """CPU seconds (user + system) of every finished process this one waited for."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def run_suite(report: Path, extra: list[str]) -> tuple[float, float, int]:
    """The suite as ``make test`` runs it: its wall time, its CPU time and pytest's exit
    code."""
    start, cpu = time.perf_counter(), _children_cpu()
    done = subprocess.run([sys.executable, "-m", "pytest", *SUITE, "-q",
                           f"--junitxml={report}", *extra], cwd=ROOT, check=False)
    return time.perf_counter() - start, _children_cpu() - cpu, done.returncode


def test_times(report: Path) -> list[tuple[float, str]]:
    """Each test case's time in a JUnit report, with its file's name and its own."""
    cases = []
    for case in ET.parse(report).iter("testcase"):
        module = case.get("classname", "").split(".")
        # NOTE: JUnit's classname is the dotted path (a class's name last, if any).
        file = next((f"{m}.py" for m in reversed(module) if f"{m}.py" in LAYER_OF), module[-1])
        cases.append((float(case.get("time", 0.0)), f"{file}::{case.get('name')}"))
    return cases


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--top", type=int, default=10, help="how many slowest tests to list")
    parser.add_argument("--write-durations", action="store_true",
                        help="write each file's seconds to tests/durations.json")
    args, extra = parser.parse_known_args()
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "suite.xml"
        wall, cpu, code = run_suite(report, extra)
        cases = test_times(report)
    files: dict[str, float] = {}
    for seconds, name in cases:
        files[name.split("::")[0]] = files.get(name.split("::")[0], 0.0) + seconds
    print(f"\nthe run: {wall:.1f} s wall, {cpu:.1f} s CPU, {len(cases)} tests")
    print(f"\n{'layer':<10} {'tests':>6} {'summed':>9}")
    for layer in ("exact", "printers", "emitted"):
        mine = [t for t, name in cases if LAYER_OF.get(name.split("::")[0]) == layer]
        print(f"{layer:<10} {len(mine):>6} {sum(mine):>8.1f}s")
    print(f"\nthe {args.top} test files whose tests take longest together:")
    for name, seconds in sorted(files.items(), key=lambda f: -f[1])[:args.top]:
        print(f"{seconds:>8.1f}s  {name}")
    print(f"\nthe {args.top} slowest tests:")
    for seconds, name in sorted(cases, reverse=True)[:args.top]:
        print(f"{seconds:>8.1f}s  {name}")
    if args.write_durations and code == 0:
        DURATIONS.write_text("{\n" + ",\n".join(
            f"{json.dumps(name)}: {round(seconds)}" for name, seconds in sorted(files.items()))
            + "\n}\n", encoding="utf-8")
        print(f"\nwrote {DURATIONS.relative_to(ROOT)}")
    return 1 if code else 0


if __name__ == "__main__":
    sys.exit(main())
