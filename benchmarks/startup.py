"""Command-line start-up: `--help`, an argument error and a small derivation, wall time of the
whole process, against two baselines measured in the same run — the bare interpreter, and
importing every stage up front (what the command line did before its imports were lazy).

    .venv/bin/python benchmarks/startup.py [runs]

Targets: `lindstedt --help` ≤ 0.3 s,
`lindstedt series duffing --order 2` ≤ 1 s.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

BIN = Path(sys.executable).parent
COMMANDS = (
    ("python -c pass (interpreter)", [sys.executable, "-c", "pass"]),
    ("import every stage (eager CLI)", [sys.executable, "-c",
                                        "import lindstedt.cli, lindstedt.charts, "
                                        "lindstedt.choose, lindstedt.emit.render, "
                                        "lindstedt.analysis.response"]),
    ("lindstedt --help", [BIN / "lindstedt", "--help"]),
    ("lindstedt driven --eps x (error)", [BIN / "lindstedt", "driven", "--eps", "x"]),
    ("lindstedt series duffing --order 2", [BIN / "lindstedt", "series", "duffing", "--order",
                                            "2"]),
)


def wall(cmd: list) -> float:
    t0 = time.perf_counter()
    subprocess.run([str(c) for c in cmd], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   check=False)
    return time.perf_counter() - t0


def main(runs: int = 7) -> None:
    for _, cmd in COMMANDS:  # warm the file cache and the bytecode
        wall(cmd)
    times = {name: [wall(cmd) for _ in range(runs)] for name, cmd in COMMANDS}
    eager = statistics.median(times["import every stage (eager CLI)"])
    print(f"{'command':<38} {'median s':>9} {'min s':>7} {'max s':>7} {'vs eager':>9}")
    for name, ts in times.items():
        med = statistics.median(ts)
        print(f"{name:<38} {med:>9.3f} {min(ts):>7.3f} {max(ts):>7.3f} {med / eager:>8.2f}×")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
