"""Fuzz the command line: every subcommand, its arguments drawn from edge values (0, negative,
huge, tiny, nan, inf, strings) and valid ones, each run in a process of its own in an empty
folder.

Every run must end with exit status 0 or 2 within ``TIMEOUT``, never print a traceback, and a
refusal (exit 2) must be one line on stderr, nothing on stdout, nothing written — not even its
--out or --plot target.  Seeded (``derandomize``) so CI draws the same runs each time,
and bounded (``max_examples`` pairs of runs per command, ~60 s for the file on a loaded
2-core machine): valid runs use small orders and harmonics, and known-slow valid regions (a
subharmonic figure, the demo, the slower scenes, --allow-slow with a large order, `generate
balance` at its default 8 harmonics) are left out of the strategies.

The second half replays, in-process and each once, the crashes and hangs known before this
fuzzing and those it found.
"""

from __future__ import annotations

import concurrent.futures
import math
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import timedelta
from pathlib import Path

import pytest
from commands import run_forked
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

TIMEOUT = 40.0
# NOTE: the slowest valid run the strategies allow (a response with a figure) takes ~15 s here.
THREADS = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
ENV = {**os.environ, **THREADS}
# NOTE: one BLAS thread: on a loaded 2-core machine OpenBLAS threads on small dense solves make
# the same run 3–7× slower, which would turn time bounds into noise.
LOG = os.environ.get("LINDSTEDT_FUZZ_LOG")
# NOTE: LINDSTEDT_FUZZ_LOG=file: one line per run (what was drawn, how it ended).
PAIR = 2
# NOTE: each example runs two command lines side by side (one per core).


def run(argv: list[str], cwd: Path, timeout: float = TIMEOUT) -> subprocess.CompletedProcess:
    """``lindstedt *argv`` in a process of its own (forked from a server that has imported
    what commands import: tests/commands.py; a sweep, whose cluster's workers are
    processes of its own, in a fresh interpreter)."""
    try:
        if argv[0] != "sweep":
            return run_forked(*argv, cwd=cwd, timeout=timeout, env=THREADS)
        return subprocess.run([sys.executable, "-m", "lindstedt", *argv], cwd=cwd, env=ENV,
                              capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        pytest.fail(f"lindstedt {' '.join(argv)}: no answer within {timeout:.0f} s")


def _run_in_empty_folder(argv: list[str]) -> tuple[subprocess.CompletedProcess, list[str], float]:
    with tempfile.TemporaryDirectory(prefix="lindstedt-fuzz-") as tmp:
        start = time.monotonic()
        out = run(argv, Path(tmp))
        seconds = time.monotonic() - start
        return out, sorted(str(p.relative_to(tmp)) for p in Path(tmp).rglob("*")), seconds


def check(*argvs: list[str]) -> None:
    """The contract of every run, each in a fresh empty folder, the runs side by side."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=len(argvs)) as pool:
        results = list(pool.map(_run_in_empty_folder, argvs))
    for argv, (out, written, seconds) in zip(argvs, results, strict=True):
        where = f"lindstedt {' '.join(map(repr, argv))}"
        if LOG:
            with open(LOG, "a") as log:
                log.write(f"{seconds:5.1f} s, exit {out.returncode}: {where} :: "
                          f"{out.stderr.strip()[-160:]!r}\n")
        assert out.returncode in (0, 2), f"{where}: exit {out.returncode}\n{out.stderr[-2000:]}"
        assert "Traceback" not in out.stderr, f"{where}:\n{out.stderr[-2000:]}"
        if out.returncode == 2:
            lines = out.stderr.strip().splitlines()
            assert len(lines) == 1, f"{where}: {len(lines)} lines on stderr:\n{out.stderr[-2000:]}"
            assert lines[0].startswith("lindstedt"), f"{where}: {lines[0]}"
            assert out.stdout == "", f"{where}: refused but printed {out.stdout[:200]!r}"
            assert written == [], f"{where}: refused but wrote {written}"


# --- strategies ------------------------------------------------------------------------------
# A run is "valid" (one in three: every value from a bounded valid range, required options
# given) or "edgy" (each value an edge one time in two, an option left out one time in eight).

EDGE_NUMBERS = ("0", "-0", "1", "-1", "0.1", "-0.1", "2", "1e-300", "-1e-300", "5e-324",
                "1e-100", "1e100", "1e300", "-1e300", "1e308", "1.8e308", "nan", "-nan", "inf",
                "-inf", "abc", "", " ", "1e", "0x10", "1_0", "1,5", "+3")
EDGE_INTEGERS = ("-1", "0", "2.5", "abc", "", "1e3", "0x10", "100000", "9" * 40)
WRITABLE_PLOTS = ("fig.png", "fig.svg", "fig.pdf")
BAD_PLOTS = ("fig.txt", "fig", "", "missing/fig.png", "/dev/null/fig.png")
WRITABLE_CSVS = ("curve.csv", "a.csv")
BAD_CSVS = ("", "missing/c.csv", "/dev/null/c.csv", ".")
WRITABLE_FOLDERS = ("out", "a/b", ".")
BAD_FOLDERS = ("", "/dev/null/x")


def real(lo: float, hi: float) -> st.SearchStrategy[str]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False).map(repr)


def whole(lo: int, hi: int) -> st.SearchStrategy[str]:
    return st.integers(lo, hi).map(str)


def maybe(strategy: st.SearchStrategy[str]) -> st.SearchStrategy[str | None]:
    """An optional flag: its value, or (None) left at its default."""
    return st.one_of(st.none(), strategy)


NUMBER = st.sampled_from(EDGE_NUMBERS)
INTEGER = st.sampled_from(EDGE_INTEGERS)
SPAN_EDGES = st.one_of(NUMBER, st.sampled_from(("1:", ":", ":1", "1:2:3:4", "2:1", "1:1",
                                                "1:2:0", "1:2:1", "1:2:abc", "nan:1", "1:inf",
                                                "0:1", "1:2:2.5", "1:2:100000")))


def span(lo: float, mid: float, hi: float, points: bool = False) -> st.SearchStrategy[str]:
    """A valid ``A:B`` (or ``A:B:N`` now and then, with ``points``) with A in [lo, mid] and B
    in [mid, hi]."""
    ends = st.tuples(real(lo, mid), real(mid, hi)).map(":".join)
    if not points:
        return ends
    return st.one_of(ends, st.tuples(ends, whole(2, 12)).map(":".join))


@dataclass(frozen=True)
class Opt:
    name: str | None  # None: a positional argument
    valid: st.SearchStrategy[str | None]  # None: left out (an optional flag at its default)
    edge: st.SearchStrategy[str]
    number: bool = True  # a value that decides whether the run computes (see `plausible`)


def plausible(values: list[str]) -> bool:
    """Every value reads as a finite number: the run may compute (and a figure take long)."""
    try:
        return all(math.isfinite(float(x)) for v in values for x in v.split(":"))
    except ValueError:
        return False


@st.composite
def command_line(draw, opts: tuple[Opt, ...], switches: tuple[str, ...] = ("--json",),
                 valid_switches: tuple[str, ...] = (), plot: str | None = None,
                 edgy: bool | None = None) -> list[str]:
    """``plot``: "fast" (a writable --plot target now and then), "slow" (a writable target
    only where a value surely fails to parse, so the figure is never drawn: a subharmonic
    figure takes half a minute) or None (no --plot).  ``edgy``: drawn unless given."""
    if edgy is None:
        edgy = draw(st.integers(0, 2)) > 0
    args, values = [], []
    for o in opts:
        if edgy and draw(st.integers(0, 7)) == 0:
            continue
        value = draw(o.edge) if edgy and draw(st.booleans()) else draw(o.valid)
        if value is None:
            continue
        if o.number:
            values.append(value)
        args += [value] if o.name is None else [o.name, value]
    for name in switches + (() if edgy else valid_switches):
        if draw(st.booleans()):
            args.append(name)
    if plot is not None:
        writable = WRITABLE_PLOTS if plot == "fast" or not plausible(values) else ()
        target = draw(st.sampled_from((None, None, *writable, *(BAD_PLOTS if edgy else ()))))
        if target is not None:
            args += ["--plot", target]
    return args


SERIES = command_line((
    Opt(None, st.sampled_from(["duffing", "pendulum", "q'' + q + eps*q**5 = 0",
                               "theta'' + sinh(theta) = 0"]),
        st.sampled_from(["nosuch", "q'' + q + eps*q'", "q'' + __import__('os')", "q'' + q",
                         "q'' + q + eps*q**999", "x''"]), number=False),
    Opt("--order", maybe(whole(0, 6)), INTEGER)), valid_switches=("--allow-slow",))
# NOTE: --allow-slow only with a small order (a large one would run for hours, as asked).

GENERATE = command_line((
    Opt(None, st.sampled_from(["duffing", "pendulum", "driven", "balance", "fourier"]),
        st.just("nosuch"), number=False),
    Opt("--order", maybe(whole(1, 2)), st.sampled_from((*EDGE_INTEGERS, "7", "13"))),
    Opt("--harmonics", whole(1, 2), st.sampled_from(("0", "13", "61", "101", "abc"))),
    Opt("--out", st.sampled_from(WRITABLE_FOLDERS), st.sampled_from(BAD_FOLDERS),
        number=False)), switches=("--allow-divergent",), valid_switches=("--allow-slow",))
# NOTE: --harmonics always small where valid: `generate balance` at the default 8 takes 20–40 s.

DRIVEN = command_line((
    Opt("--eps", real(-0.3, 1.0), NUMBER), Opt("--force", real(-1.5, 1.5), NUMBER),
    Opt("--omega", real(0.3, 2.5), NUMBER),
    Opt("--Q", maybe(st.one_of(real(2.0, 50.0), st.just("inf"))), NUMBER),
    Opt("--order", maybe(whole(0, 3)), st.sampled_from((*EDGE_INTEGERS, "16", "201"))),
    Opt("--harmonics", maybe(whole(1, 4)), st.sampled_from(("0", "17", "100", "101", "abc")))))

RESPONSE = command_line((
    Opt("--eps", real(-0.2, 0.5), NUMBER), Opt("--force", real(0.05, 1.0), NUMBER),
    Opt("--Q", real(2.0, 40.0), NUMBER),
    Opt("--harmonics", maybe(whole(1, 3)), st.sampled_from(("0", "101", "100000", "abc")))),
    plot="fast")

SUBHARMONIC = command_line((
    Opt("--eps", real(-0.3, 1.0), NUMBER), Opt("--force", real(-1.0, 1.0), NUMBER),
    Opt("--omega", real(0.2, 2.5), NUMBER)), plot="slow")

PARAMETRIC = command_line((
    Opt("--eps", real(0.01, 0.9), NUMBER), Opt("--zeta", maybe(real(0.0, 0.1)), NUMBER),
    Opt("--gamma", maybe(real(-2.0, 2.0)), NUMBER),
    Opt("--omega", span(0.5, 1.0, 1.5, points=True), SPAN_EDGES),
    Opt("--harmonics", maybe(whole(1, 8)), st.sampled_from(("0", "101", "abc")))), plot="slow")
# NOTE: its figure (221 ω, ~7 s) only where a value fails to parse, as the subharmonic's.

EDGE_DRIVES = ("0.3", "1@", "@", "1@2@3", "abc@1", "0.3@-1", "-0.3@1.3", "0@1", "1e308@1e308",
               "0.3@1e5", "nan@1", "1@inf", "1e100@1", "0.3@1e-100")
DRIVE = st.tuples(real(-0.5, 0.5), real(0.3, 2.2)).map("@".join)


@st.composite
def mixing(draw) -> list[str]:
    edgy = draw(st.integers(0, 2)) > 0
    args = draw(command_line((Opt("--eps", real(-0.2, 0.5), NUMBER),
                              Opt("--Q", real(2.0, 30.0), NUMBER)), plot="fast", edgy=edgy))
    drives = draw(st.lists(st.one_of(DRIVE, st.sampled_from(EDGE_DRIVES)) if edgy else DRIVE,
                           min_size=0 if edgy else 1, max_size=6 if edgy else 2))
    return [*args, *(a for d in drives for a in ("--drive", d))]


CHOOSE = command_line((
    Opt(None, st.sampled_from(["period", "amplitudes", "response"]),
        st.sampled_from(["nosuch", "q"]), number=False),
    Opt("--tol", real(1e-6, 1e-3), NUMBER), Opt("--range", span(-0.5, 0.2, 1.0), SPAN_EDGES),
    Opt("--t-max", maybe(real(1.0, 10.0)), NUMBER),
    Opt("--eps", real(0.0, 0.3), NUMBER), Opt("--force", real(0.1, 1.0), NUMBER),
    Opt("--omega", real(0.6, 1.6), SPAN_EDGES), Opt("--Q", maybe(real(5.0, 50.0)), NUMBER),
    Opt("--out", st.none(), st.sampled_from((*BAD_FOLDERS, "out")), number=False)))
# NOTE: valid runs verify one ω (a range takes 8 s and more), emit nothing (choosing with
# --out may generate the order-6 μ-expansion: minutes) and leave out `q` (11–16 s); edgy runs
# draw them, where other values may be bad, and a refusal's --out target must stay unwritten.

NNM = command_line((
    Opt(None, st.sampled_from(["x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0",
                               "x1'' + 2*x1 - x2 + x1**2 = 0; x2'' + 2*x2 - x1 = 0",
                               "1.2*x1'' + 0.3*x2'' + 2.5*x1 - 1.1*x2 + 0.4*x1**3 = 0; "
                               "0.3*x1'' + 0.8*x2'' - 1.1*x1 + 1.7*x2 = 0"]),
        st.sampled_from(["x1'' + x1", "x1'' + x1 + x2 = 0; x1'' = 0", ";", "",
                         "x1'' + 2*x2'' + x1 + x1**3 = 0; 2*x1'' + x2'' + x2 = 0",
                         "x1'' + x2'' + x1 + x1**3 = 0; 2*x1'' + x2'' + x2 = 0",
                         "x1'' + __import__('os') = 0; x2'' = 0", "x1'' - x1 = 0; x2'' + x2 = 0",
                         "x1'' + x1 + (x1 + x2)**3 = 0; x2'' + 9*x2 + (x1 + x2)**3 = 0",
                         "x1'' + x1 + x1' = 0; x2'' + x2 = 0", "x1'' + k*x1 = 0; x2'' + x2 = 0",
                         "x1'' + x1 + x1**99 = 0; x2'' + x2 = 0"]), number=False),
    Opt("--mode", maybe(whole(1, 2)), INTEGER), Opt("--order", maybe(whole(0, 8)), INTEGER),
    Opt("--amplitude", maybe(st.sampled_from(["x1", "x2"])), st.sampled_from(["x3", "", "A"]),
        number=False)), plot="slow")
# NOTE: the figure shoots 16 orbits (~7 s): only where a value fails to parse.

RESPONSE_SYSTEM = command_line((
    Opt(None, st.sampled_from(["x1'' + x1'/20 + 2*x1 - x2 + x1**3/2 = f*cos(w*t); "
                               "x2'' + x2'/20 + 2*x2 - x1 = 0",
                               "2*x1'' + x2'' + 0.05*x1' + 3*x1 - x2 + x1**3 = f*cos(w*t); "
                               "x1'' + 2*x2'' + 0.05*x2' - x1 + 2*x2 = 0"]),
        st.sampled_from(["x1'' + 2*x1 - x2 = f*cos(w*t); x2'' + 2*x2 - x1 = 0", ";",
                         "x1'' + x1'/20 + x1 = f*sin(w*t); x2'' + x2 = 0",
                         "x1'' + x1'/20 + x1 = f*x1*cos(w*t); x2'' + x2'/20 + x2 = 0",
                         "x1'' + x1'/20 + x1 = f*cos(w*t); x2'' + x2 = f*cos(v*t)",
                         "x1'' + x1'/20 - x1 = f*cos(w*t); x2'' + x2'/20 + x2 = 0",
                         "x1'' + __import__('os') = f*cos(w*t); x2'' = 0"]), number=False),
    Opt("--param", st.just("f=3/10"), st.sampled_from(["f=abc", "w=1", "g=1", "f=1e400"]),
        number=False),
    Opt("--omega", span(0.9, 1.0, 1.3), SPAN_EDGES),
    Opt("--harmonics", maybe(whole(1, 3)), st.sampled_from(("0", "101", "abc")))), plot="slow")
# NOTE: a driven system's response over a short range at N ≤ 3 harmonics (2–4 s a valid run).

SSM = command_line((
    Opt(None, st.sampled_from([
        "x1'' + 0.02*x1' + 2*x1 - x2 + x1**3 = f*cos(w*t); "
        "x2'' + 0.02*x2' + 2*x2 - x1 + 0.5*x2**2 = 0",
        "1.2*x1'' + 0.3*x2'' + 0.01*x1' + 2.5*x1 - 1.1*x2 + 0.4*x1**3 = f*cos(w*t); "
        "0.3*x1'' + 0.8*x2'' + 0.01*x2' - 1.1*x1 + 1.7*x2 = 0",
        "x1'' + 0.1*x1' + 1e10*x1 - x2 + x1**3 = f*cos(w*t); x2'' + 0.1*x2' + 2*x2 - x1 = 0",
        "x1'' + 0.05*x1' + x1 = f*cos(w*t); x2'' + 0.05*x2' + 3*x2 = 0",
        "x'' + 0.1*x' + x + x**2 + x**3 = f*cos(w*t)"]),
        st.sampled_from([";", "x1'' + x1 + (x1 + x2)**3 = 0; x2'' + 9*x2 + (x1 + x2)**3 = 0",
                         "x1'' + __import__('os') = 0; x2'' = 0", "x'' + 3*x' + x = 0",
                         "x1'' - x1 = 0; x2'' + x2 = 0", "x'' + x' + x = f*x*cos(w*t)"]),
        number=False),
    Opt("--param", st.just("f=1/100"), st.sampled_from(["f=abc", "g=1", "f=1e400"]),
        number=False),
    Opt("--mode", maybe(whole(1, 2)), INTEGER), Opt("--order", maybe(whole(1, 9)), INTEGER),
    Opt("--omega", maybe(span(0.5, 1.0, 1.5, points=True)), SPAN_EDGES),
    Opt("--rho-max", maybe(st.sampled_from(["0.01", "0.1"])), NUMBER),
    Opt("--output", maybe(st.sampled_from(["0", "x1", "0,1"])),
        st.sampled_from(["7", "x9", "0,0", ""]), number=False)), plot="fast")
# NOTE: a damped pair with decimals, a full mass matrix, a stiffness of 1e10, a linear pair,
# one coordinate; an exact 1:3 resonance, an overdamped mode, injection (1–3 s a valid run).

SLOWFLOW_SYSTEM = command_line((
    Opt(None, st.sampled_from(["x1'' + x1 + x1*x2 = 0; x2'' + 4*x2 + x1**2/2 = 0",
                               "x1'' + x1 + 0.3*x1*x2 = 0; x2'' + 4.0*x2 + 0.15*x1**2 = 0"]),
        st.sampled_from(["x1'' + x1 = 0; x2'' + 9*x2 = 0", "x1'' + x1 + x2**3 = 0; x2'' + 2*x2",
                         "x1'' + x1 + x1*x2 = 0; x2'' + 5*x2 + x1**2 = 0",
                         "x1'' + x1 + __import__('os') = 0; x2'' + 4*x2 = 0"]), number=False),
    Opt("--start", maybe(st.sampled_from(["a1=0.02", "a2=0.05"])),
        st.sampled_from(["a3=1", "a1=-1", "a1=abc", "a1=1e40", "a1=1000", "=1"]),
        number=False),
    Opt("--csv", maybe(st.sampled_from(WRITABLE_CSVS)), st.sampled_from(BAD_CSVS),
        number=False)), plot="fast")
# NOTE: a system's first-order slow flow in 1:2 resonance, exact and decimal (1–4 s a valid
# run, its energy exchange drawn and tabulated now and then).

GENERATE_SYSTEM = command_line((
    Opt(None, st.sampled_from(["x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0",
                               "x1'' + x1 + 0.5*(x1-x2) + 0.3*x1**3 = 0; "
                               "x2'' + 1.21*x2 + 0.5*(x2-x1) = 0",
                               "1.2*x1'' + 0.3*x2'' + 2.5*x1 - 1.1*x2 + 0.4*x1**3 = 0; "
                               "0.3*x1'' + 0.8*x2'' - 1.1*x1 + 1.7*x2 + 0.2*x2**3 = 0"]),
        st.sampled_from(["x1'' + x1 = 0; x2'' + 9*x2 = 0",
                         "x1'' + x1 + x1**3 = 0; x2'' + 9*x2 + x2**3 = 0", ";",
                         "x1'' + 2*x1 - x2 + k*x1**3 = 0; x2'' + 2*x2 - x1 = 0"]),
        number=False),
    Opt("--mode", whole(1, 2), INTEGER), Opt("--order", maybe(whole(1, 4)), INTEGER),
    Opt("--name", maybe(st.just("pair")), st.sampled_from(["numpy", "1x", "a-b", ""]),
        number=False),
    Opt("--out", st.sampled_from(WRITABLE_FOLDERS), st.sampled_from(BAD_FOLDERS),
        number=False)))
# NOTE: a normal mode's module to order ≤ 4 (written, not compiled: 1–5 s a valid run); the
# stiff systems (1e10–1e30, ~10 s at the default order) have tests of their own.

CHOOSE_BACKBONE = command_line((
    Opt(None, st.just("backbone"), st.sampled_from(["backbones", ""]), number=False),
    Opt(None, st.sampled_from(["x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0",
                               "x1'' + 1.5*x1 - 0.5*x2 + 0.2*x1**3 = 0; "
                               "x2'' + 1.7*x2 - 0.5*x1 = 0"]),
        st.sampled_from(["x1'' + x1 = 0; x2'' + 9*x2 = 0", ";",
                         "x1'' + x1 + x1**3 = 0; x2'' + x2 + x2**3 = 0"]), number=False),
    Opt("--mode", whole(1, 2), INTEGER), Opt("--tol", real(1e-6, 1e-3), NUMBER),
    Opt("--range", span(0.01, 0.05, 0.2), SPAN_EDGES)))
# NOTE: a normal mode's smallest order for a tolerance over a small range (~8 s a valid run).

CLOCK = st.sampled_from([[], ["--json"], ["--bogus"], ["extra"], ["--json", "--json"]])

MODELS = st.sampled_from([[], ["--json"], ["--bogus"], ["extra"], ["--json", "--json"]])

SWEEP_SYSTEM = command_line((
    Opt(None, st.just("response"), st.sampled_from(["stability", "validity", "nosuch"]),
        number=False),
    Opt(None, st.sampled_from(["x1'' + 0.05*x1' + 2*x1 - x2 + 0.5*x1**3 = f*cos(w*t); "
                               "x2'' + 0.05*x2' + 2*x2 - x1 = 0",
                               "2*x1'' + x2'' + 0.1*x1' + 3*x1 - x2 + 0.3*x1**3 = f*cos(w*t); "
                               "x1'' + 2*x2'' + 0.1*x2' - x1 + 2*x2 = 0"]),
        st.sampled_from(["x1'' + 2*x1 - x2 = f*cos(w*t); x2'' + 2*x2 - x1 = 0", ";",
                         "x1'' + x1'/20 + x1 + x1**3 = 0; x2'' + x2'/20 + x2 = 0",
                         "x1'' + 2*x2'' + x1' + x1 = f*cos(w*t); 2*x1'' + x2'' + x2 = 0",
                         "x1'' + __import__('os') = f*cos(w*t); x2'' = 0"]), number=False),
    Opt("--axis", st.just("w=1.0:1.2:2"),
        st.sampled_from(["w=1:1.2:0", "zz=1:2:2", "w=abc", "f=1e400:1:2", "r_x1=1:2:2"]),
        number=False),
    Opt("--param", st.just("f=1/10"), st.sampled_from(["f=abc", "w=1", "g=1", "f=1e400"]),
        number=False),
    Opt("--workers", st.just("1"), st.sampled_from(["0", "-1", "abc"]), number=False),
    Opt("--out", st.sampled_from(["store", "a/store"]), st.sampled_from(BAD_FOLDERS),
        number=False)))
# NOTE: a driven system's map over two ω on one worker (a dask cluster each: 5–8 s a valid
# run), exact and decimal, a full mass among them.

MATHIEU = command_line((
    Opt(None, st.sampled_from(["a", "b"]), st.sampled_from(["c", "", "A"]), number=False),
    Opt("--m", maybe(whole(1, 6)), INTEGER), Opt("--order", maybe(whole(0, 30)), INTEGER)))

TONGUES = command_line((
    Opt(None, st.sampled_from(["cos(t)", "cos(t) + 1/2*cos(2*t)", "sin(t)", "cos(t) + sin(2*t)"]),
        st.sampled_from(["cos(sqrt(2)*t)", "t*cos(t)", "cos(t/2)", "a*cos(t)", "1", "",
                         "__import__('os')", "cos(t) + sin(t)", "cos(99*t)"]), number=False),
    Opt("--n", maybe(whole(0, 4)), INTEGER), Opt("--order", maybe(whole(0, 20)), INTEGER),
    Opt("--zeta", maybe(real(0.0, 0.1)), NUMBER), Opt("--eps", maybe(real(-0.5, 0.5)), NUMBER),
    Opt("--tol", maybe(real(1e-12, 1e-3)), NUMBER)), switches=("--json", "--singularities"),
    plot="slow")
# NOTE: a chart (two 400 × 400 Floquet grids, ~15 s) only where a value fails to parse.

SCENE = command_line((Opt(None, st.just("clock"), st.sampled_from(["nosuch", "CLOCK", ""]),
                          number=False),))
# NOTE: hard-spring (14 s) and notes-driven (9 s) are valid but slow; `choose` covers them.

DEMO = st.tuples(st.sampled_from(BAD_FOLDERS), st.sampled_from([[], ["--bogus"]])).map(
    lambda p: ["--out", p[0], *p[1]])
# NOTE: a valid demo runs for minutes (the `make demo` target); only refusals are fuzzed.

SLOWFLOW = command_line((
    Opt(None, st.sampled_from(["van_der_pol", "rayleigh",
                               "q'' + q = eps*(-k*q' - q**3 + F*cos(w*t))"]),
        st.sampled_from(["nosuch", "q'' + q + q**3 = 0", "2*q'' + q = eps*q'",
                         "q'' + q = eps*sin(q)", "q'' + q = eps*q'*cos(t)*q",
                         "q'' + q = eps*r*q'", "q'' + __import__('os')"]), number=False),
    Opt("--order", maybe(whole(1, 3)), INTEGER),
    Opt("--out", maybe(st.sampled_from(WRITABLE_FOLDERS)), st.sampled_from(BAD_FOLDERS),
        number=False)))

BUDGET = {"series": (SERIES, 2), "generate": (GENERATE, 2), "driven": (DRIVEN, 4),
          "response": (RESPONSE, 3), "subharmonic": (SUBHARMONIC, 2),
          "mixing": (mixing(), 3), "choose": (CHOOSE, 2), "clock": (CLOCK, 1),
          "scene": (SCENE, 1), "demo": (DEMO, 1), "models": (MODELS, 1),
          "mathieu": (MATHIEU, 2), "parametric": (PARAMETRIC, 2),
          "slowflow": (SLOWFLOW, 2), "tongues": (TONGUES, 2), "nnm": (NNM, 2),
          "response SYSTEM": (RESPONSE_SYSTEM, 2), "slowflow SYSTEM": (SLOWFLOW_SYSTEM, 2),
          "generate SYSTEM": (GENERATE_SYSTEM, 2), "choose SYSTEM": (CHOOSE_BACKBONE, 1),
          "ssm": (SSM, 2),
          "sweep SYSTEM": (SWEEP_SYSTEM, 1)}
# NOTE: examples (pairs of runs side by side) per command: 64 runs, the file ~60 s on the
# 2-core machine with other work loading it (a refusal takes 0.1–3 s, a valid run 2–8 s).


def _fuzz(key: str):
    strategy, examples = BUDGET[key]
    command = key.split()[0]

    @settings(max_examples=examples, derandomize=True, database=None,
              deadline=timedelta(seconds=TIMEOUT + 10), phases=(Phase.explicit, Phase.generate),
              suppress_health_check=list(HealthCheck))
    @given(args=st.lists(strategy, min_size=PAIR, max_size=PAIR, unique_by=tuple))
    def test(args: list[list[str]]) -> None:
        check(*([command, *a] for a in args))

    test.__name__ = f"test_fuzz_{key.replace(' ', '_').lower()}"
    return test


test_fuzz_series = _fuzz("series")
test_fuzz_generate = _fuzz("generate")
test_fuzz_ssm = _fuzz("ssm")
test_fuzz_driven = _fuzz("driven")
test_fuzz_response = _fuzz("response")
test_fuzz_subharmonic = _fuzz("subharmonic")
test_fuzz_mixing = _fuzz("mixing")
test_fuzz_choose = _fuzz("choose")
test_fuzz_clock = _fuzz("clock")
test_fuzz_scene = _fuzz("scene")
test_fuzz_demo = _fuzz("demo")
test_fuzz_models = _fuzz("models")
test_fuzz_mathieu = _fuzz("mathieu")
test_fuzz_tongues = _fuzz("tongues")
test_fuzz_slowflow = _fuzz("slowflow")
test_fuzz_parametric = _fuzz("parametric")
test_fuzz_nnm = _fuzz("nnm")
test_fuzz_response_system = _fuzz("response SYSTEM")
test_fuzz_slowflow_system = _fuzz("slowflow SYSTEM")
test_fuzz_generate_system = _fuzz("generate SYSTEM")
test_fuzz_choose_system = _fuzz("choose SYSTEM")
test_fuzz_sweep_system = _fuzz("sweep SYSTEM")


NOT_FUZZED: dict[str, str] = {}
# NOTE: a new subcommand must join BUDGET, or be listed here with the reason (sweep's
# equation and notes' kinds are covered by tests/test_sweep.py; a system's through the fuzz).


def test_every_subcommand_is_fuzzed():
    from lindstedt.cli import build_parser

    commands = build_parser()._subparsers._group_actions[0].choices
    assert set(commands) - set(NOT_FUZZED) == {key.split()[0] for key in BUDGET}


# --- the cases the fuzzing found: each once --------------------------------------------------

D = ["driven", "--eps", "0.1", "--force", "1", "--omega", "1"]
REFUSED = [
    # (argv, what the one line must name)
    (["driven", "--eps", "0.1", "--force", "0", "--omega", "1"], "force 0: no drive"),
    (["driven", "--eps=-0.1", "--force", "1", "--omega", "1e-300"], "omega 1e-300"),
    (["response", "--eps", "0.1", "--force", "5e-324", "--Q", "10", "--plot", "out.pdf"],
     "force 5e-324"),
    (["response", "--eps", "0.1", "--force", "1e30", "--Q", "185"], "force 1e+30"),
    (["response", "--eps", "0.1", "--force", "1e6", "--Q", "185", "--harmonics", "60"],
     "eps = 0.1, f = 1000000.0): the response curve spans"),
    (["response", "--eps", "0.1", "--force", "0.3", "--Q", "20", "--harmonics", "100000"],
     "--harmonics: 100000: must be in 1..100"),
    (["subharmonic", "--eps", "1e-308", "--force", "1", "--omega", "1.1"], "eps 1e-308"),
    (["mixing", "--eps", "0.1", "--Q", "1e300", "--drive", "0.3@1"], "Q 1e+300"),
    (["mixing", "--eps", "0.1", "--Q", "1e12", "--drive", "0.3@1.3"], "Q 1e+12: the transients"),
    (["mixing", "--eps", "0.1", "--Q", "10", "--drive", "1e308@1e308", "--drive", "0.3@1.3"],
     "drive 1e+308@1e+308"),
    (["mixing", "--eps", "0.1", "--Q", "10", *[a for k in range(5)
                                               for a in ("--drive", f"0.1@{1 + k / 10}")]],
     "drives: 5 given, at most 4"),
    (["choose", "amplitudes", "--eps", "0.1", "--force", "1", "--omega", "1", "--Q", "1e-308"],
     "Q 1e-308"),
    ([*D, "--harmonics", "101"], "--harmonics: 101: must be in 1..100"),
    # found by this fuzzing and its probes of the domain's corners
    (["choose", "amplitudes", "--eps", "0", "--force", "1", "--omega", "1"],
     "eps 0, Q inf, omega 1: an undamped linear oscillator"),  # IndexError
    (["response", "--eps", "0", "--force", "1e-16", "--Q", "1e16"],
     "the damping 1e-16*q' makes the resonance 1e-16 wide"),  # the continuation wandered for good
    (["mixing", "--eps=-0.1", "--Q", "10", "--drive", "1e16@1e-16"],
     "drive 1e+16@1e-16: frequency below"),  # ValueError: no tone above 1e-12
    (["mixing", "--eps=-0.1", "--Q", "10", "--drive", "3@1"], "escapes to infinity"),
    (["series", "duffing", "--order", "1" + "0" * 400], "more than 1e300 s"),  # OverflowError
    (["driven", "--eps", "1e100", "--force", "1e100", "--omega", "1e100", "--Q", "1e-100"],
     "eps 1e+100"),  # LinAlgError in np.roots: ω²/Q² overflowed
]


def call(args: list[str], cwd: Path, monkeypatch, capsys) -> tuple[int, str, str, list]:
    """``lindstedt ARGS`` in-process (one import for all the cases), in the empty ``cwd``."""
    from lindstedt.cli import main

    monkeypatch.chdir(cwd)
    try:
        status = main(args)
    except SystemExit as exc:  # argparse's refusals
        status = exc.code
    out = capsys.readouterr()
    return status, out.out, out.err, sorted(cwd.rglob("*"))


@pytest.mark.parametrize("args,needle", REFUSED, ids=[needle for _, needle in REFUSED])
def test_found_cases_are_refused_in_one_line(args, needle, tmp_path, monkeypatch, capsys):
    status, out, err, written = call(args, tmp_path, monkeypatch, capsys)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], err
    assert out == "" and written == []


def test_found_cases_within_the_advertised_range_are_answered(tmp_path, monkeypatch, capsys):
    """``--order 16``, ``--harmonics 17`` (advertised 0..200, 1..100) once raised IndexError:
    shooting sampled q too coarsely for the harmonics asked."""
    import json

    status, out, err, _ = call([*D, "--order", "16", "--harmonics", "17", "--json"], tmp_path,
                               monkeypatch, capsys)
    assert status == 0, err
    branch = json.loads(out)["branches"][0]
    assert len(branch["numerical"]["A"]) == 17  # odd harmonics 1..33
    assert abs(branch["numerical"]["A"]["1"] - branch["harmonic_balance"]["A"]["1"]) < 1e-9


def test_closed_stdout_is_not_a_traceback():
    """``lindstedt clock --json | head -c 0``: the reader has gone before the first write;
    the Python docs' recipe for BrokenPipeError (exit 1, no traceback)."""
    with tempfile.TemporaryDirectory(prefix="lindstedt-pipe-") as tmp:
        proc = subprocess.Popen([sys.executable, "-m", "lindstedt", "clock", "--json"],
                                cwd=tmp, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        proc.stdout.close()  # before the command has written anything
        _, err = proc.communicate(timeout=TIMEOUT)
    assert proc.returncode == 1, err.decode()
    assert err.decode() == ""
