"""Every command's cost estimate against the measured wall time of the same command.

    .venv/bin/python benchmarks/command_costs.py [--quick] [--only COMMAND]

Each command runs at several sizes (into a temporary folder, with --allow-slow where it has
one); the table prints the estimate `lindstedt.costs.COSTS` gives for the same command line,
the measured time and their ratio (a command that exits 2 is shown as such).  The estimates
decide when a command asks for --allow-slow (above 60 s).  `--quick` skips estimates above
30 s; `--only COMMAND` runs one command's cases.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from lindstedt.cli import build_parser, check_cost
from lindstedt.costs import COSTS

BIN = Path(sys.executable).parent / "lindstedt"
DRIVE = ["--eps", "0.1", "--force", "0.3"]
CASES = [
    *[["generate", "duffing", "--order", str(k)] for k in (20, 60, 100, 130)],
    *[["generate", "pendulum", "--order", str(k)] for k in (20, 40, 60, 80)],
    *[["generate", "balance", "--harmonics", str(n)] for n in (2, 4, 8, 12)],
    *[["generate", "fourier", "--harmonics", str(n)] for n in (8, 40)],
    *[["generate", "driven", "--order", str(k)] for k in (3, 4, 5)],
    *[["series", "duffing", "--order", str(k), "--json"] for k in (100, 200, 300)],
    *[["series", "pendulum", "--order", str(k), "--json"] for k in (40, 70, 100)],
    *[["series", "q'' + q + eps*q**5 = 0", "--order", str(k), "--json"] for k in (50, 100)],
    ["series", "q'' + q + eps*q**9 = 0", "--order", "60", "--json"],
    ["series", "q'' + q + eps*(alpha*q**2 + q**3) = 0", "--order", "30", "--json"],
    ["series", "q'' + q + eps*(q**5 + 2*q**3*q'**2 + q*q'**4/3) = 0", "--order", "100", "--json"],
    ["generate", "q'' + q + eps*(q**2 + q**3) = 0", "--name", "hd", "--order", "8"],
    *[["driven", *DRIVE, "--omega", "1.3", "--order", str(k), "--json"] for k in (4, 64, 100,
                                                                               150, 200)],
    *[["driven", *DRIVE, "--omega", "1.3", "--Q", "20", "--order", str(k), "--json"]
      for k in (4, 100)],
    *[["response", *DRIVE, "--Q", "20", "--harmonics", str(n), "--json"] for n in (8, 40)],
    ["response", "--eps", "0.1", "--force", "1", "--Q", "50", "--harmonics", "20", "--json"],
    ["subharmonic", *DRIVE, "--omega", "1.05", "--json"],
    ["mixing", "--eps", "0.1", "--Q", "20", "--drive", "0.3@0.8", "--drive", "0.2@1.9",
     "--drive", "0.1@2.7", "--drive", "0.1@3.3", "--json"],
    ["choose", "period", "--tol", "1e-8", "--range", "-0.5:0.5", "--json"],
    ["choose", "q", "--tol", "1e-6", "--range", "0:0.5", "--json"],
    ["choose", "amplitudes", *DRIVE, "--Q", "20", "--omega", "1.3", "--json"],
    ["choose", "response", *DRIVE, "--Q", "20", "--omega", "0.5:1.5",
     "--json"],
    ["choose", "amplitudes", *DRIVE, "--omega", "1.3", "--tol", "1e-6", "--json"],
    ["clock", "--json"],
    *[["scene", name, "--json"] for name in ("clock", "hard-spring", "notes-driven")],
    *[["sweep", "stability", "--omega", f"1.0:1.5:{n}", "--force", "0.3", "--eps", "0.1",
       "--Q", "20", "--json"] for n in (64, 512)],
    ["sweep", "validity", "--omega", "0.5:1.5:128", "--force", "0.3", "--eps", "0.1", "--Q",
     "inf", "--json"],
]
SLOW = {"series", "generate", "driven", "response", "choose", "sweep", "mathieu"}
# NOTE: the commands that take --allow-slow (the others never exceed the limit).


def wall(args: list[str]) -> tuple[float, int]:
    t0 = time.perf_counter()
    done = subprocess.run([str(BIN), *args], check=False, stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0, done.returncode


def main(quick: bool, only: str | None) -> None:
    print(f"{'command':<78} {'estimate s':>10} {'measured s':>10} {'ratio':>6}")
    with tempfile.TemporaryDirectory() as tmp:
        for i, case in enumerate(CASES):
            if only and case[0] != only:
                continue
            args = list(case)
            if args[0] == "generate":
                args += ["--out", f"{tmp}/g{i}"]
            if args[0] == "sweep":
                args += ["--out", f"{tmp}/s{i}.zarr"]
            if args[0] in SLOW:
                args.append("--allow-slow")
            parsed = build_parser().parse_args(args)
            check_cost(parsed)  # bounds hold
            estimate = COSTS[parsed.command](parsed).seconds
            if quick and estimate > 30:
                continue
            measured, status = wall(args)
            label = " ".join(a for a in case if a != "--json")
            ratio = f"{measured / estimate:>6.2f}" if status == 0 else f"exit {status}"
            print(f"{label:<78} {estimate:>10.1f} {measured:>10.1f} {ratio:>6}", flush=True)


if __name__ == "__main__":
    argv = sys.argv[1:]
    main("--quick" in argv, argv[argv.index("--only") + 1] if "--only" in argv else None)
