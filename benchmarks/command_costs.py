"""The command line's cost estimates against the measured wall time of the same commands.

    .venv/bin/python benchmarks/command_costs.py [--quick]

Each `lindstedt generate MODEL` runs at several sizes (into a temporary folder, with
--allow-slow); the table prints the estimate `lindstedt.cli.generate_seconds` gives, the
measured time and their ratio, and `series` likewise against `estimated_seconds`. The
estimates decide when a command asks for --allow-slow (above 60 s).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from lindstedt.cli import estimated_seconds, generate_seconds

BIN = Path(sys.executable).parent / "lindstedt"
GENERATE = (("duffing", "--order", (20, 60, 100, 130)), ("pendulum", "--order", (20, 40, 60, 80)),
            ("balance", "--harmonics", (2, 4, 8, 12)), ("fourier", "--harmonics", (8, 40)),
            ("driven", "--order", (3, 4, 5)))
SERIES = (("duffing", (100, 200, 300)), ("pendulum", (40, 70, 100)))


def wall(args: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run([str(BIN), *args], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main(quick: bool) -> None:
    print(f"{'command':<48} {'estimate s':>10} {'measured s':>10} {'ratio':>6}")
    with tempfile.TemporaryDirectory() as tmp:
        for model, flag, sizes in GENERATE:
            for size in sizes[:2] if quick else sizes:
                args = ["generate", model, flag, str(size), "--out", f"{tmp}/{model}{size}",
                        "--allow-slow"]
                estimate, measured = generate_seconds(model, size), wall(args)
                print(f"{' '.join(args[:4]):<48} {estimate:>10.1f} {measured:>10.1f} "
                      f"{measured / estimate:>6.2f}")
    for model, orders in SERIES:
        for order in orders[:1] if quick else orders:
            args = ["series", model, "--order", str(order), "--json", "--allow-slow"]
            estimate, measured = estimated_seconds(model, order), wall(args)
            print(f"{' '.join(args[:4]):<48} {estimate:>10.1f} {measured:>10.1f} "
                  f"{measured / estimate:>6.2f}")


if __name__ == "__main__":
    main("--quick" in sys.argv[1:])
