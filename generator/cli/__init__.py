"""The ``lindstedt`` command line.  Bad input: one line on stderr, exit status 2.

One module per command family (:mod:`.series`, :mod:`.system`, :mod:`.driven`,
:mod:`.response`, :mod:`.ssm`, :mod:`.choose`, :mod:`.sweep`, :mod:`.demo`), each with its commands'
arguments, JSON contracts and tables;
:data:`COMMANDS` here lists them for the parser, the cost guard and ``--help``."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NoReturn

from .. import __version__
from ..costs import COSTS, ROUTE_COSTS
from ..derive.problem import NOTES_PRESET, Problem, read_problem
from ..errors import InputError, Interrupted, clipped
from ..limits import COST_LIMIT_SECONDS, SLOW_LIMIT_SECONDS
from .choose import (
    arguments_choose,
    arguments_clock,
    arguments_scene,
    run_choose,
    run_clock,
    run_scene,
)
from .common import _Parser
from .demo import arguments_demo, run_demo
from .driven import (
    arguments_driven,
    arguments_mixing,
    arguments_parametric,
    arguments_subharmonic,
    run_driven,
    run_mixing,
    run_parametric,
    run_subharmonic,
)
from .response import arguments_response, run_response
from .series import (
    arguments_generate,
    arguments_mathieu,
    arguments_models,
    arguments_series,
    arguments_tongues,
    run_generate,
    run_generate_mode,
    run_mathieu,
    run_models,
    run_series,
    run_tongues,
)
from .slowflow import arguments_slowflow, run_resonant_modes, run_slowflow
from .ssm import arguments_ssm, run_ssm
from .sweep import arguments_sweep, run_sweep
from .system import arguments_nnm, run_nnm


@dataclass(frozen=True)
class Route:
    """One method of a command, as data: the problems it takes (``applies``: ``None``, else
    why not), the function that runs it and its cost estimate (checked before it runs;
    ``None``: too quick to estimate)."""

    method: str
    applies: Callable[[Problem | None], str | None]
    run: Callable[[argparse.Namespace], int]
    cost: Callable[[argparse.Namespace], object] | None


def _any(problem: Problem | None) -> None:
    """Every problem the command's parser takes."""
    return None


def _one_coordinate(problem: Problem | None) -> str | None:
    """One coordinate (an equation, a preset, a name, the notes' driven Duffing's flags): the
    one-coordinate kernels, the fast path of every method they share with systems."""
    if problem is None or problem.one_coordinate:
        return None
    return f"{problem.size} coordinates"


def _coordinates(problem: Problem | None) -> str | None:
    """A system of equations (one per coordinate)."""
    return None if problem is not None and problem.size else "no equations"


@dataclass(frozen=True)
class Command:
    """One command: its name, the function that adds its arguments (a subparser) and its
    routes, the methods it runs, in order: the first whose problems hold the command's
    problem (:func:`derive.problem.read_problem` of its ``MODEL``) runs.  The parser, the cost
    guard and ``--help`` loop over :data:`COMMANDS`."""

    name: str
    arguments: Callable[[argparse._SubParsersAction], argparse.ArgumentParser]
    routes: tuple[Route, ...]
    notes: bool = False  # without MODEL: the notes' driven Duffing, eq. 10.60, by its flags

    def route(self, args: argparse.Namespace) -> Route:
        """The method that takes ``args``' problem; one line naming each method's reason
        where none does.  Where the command's problem without MODEL is the notes' driven
        Duffing, its preset's name (``duffing``) stands for it: the same flags, the same
        answer."""
        text = getattr(args, "model", None)
        problem = read_problem(text) if isinstance(text, str) else None
        if self.notes and problem is not None and problem.preset == NOTES_PRESET:
            args.model, problem = None, None
        reasons = []
        for route in self.routes:
            why = route.applies(problem)
            if why is None:
                return route
            reasons.append(f"{route.method}: {why}")
        raise InputError(f"{self.name} {text!r}: no method takes it ({'; '.join(reasons)})")


def _command(name: str, arguments: Callable, run: Callable, *others: Route,
             notes: bool = False) -> Command:
    """A command whose first method takes one coordinate (else every problem its parser
    takes, where it has no ``others``), with its estimate :data:`costs.COSTS`."""
    first = Route(name, _one_coordinate if others else _any, run, COSTS.get(name))
    return Command(name, arguments, (first, *others), notes)


COMMANDS: tuple[Command, ...] = (
    _command("series", arguments_series, run_series),
    _command("mathieu", arguments_mathieu, run_mathieu),
    _command("tongues", arguments_tongues, run_tongues),
    _command("models", arguments_models, run_models),
    _command("generate", arguments_generate, run_generate,
             Route("normal mode", _coordinates, run_generate_mode,
                   ROUTE_COSTS["generate normal mode"])),
    _command("nnm", arguments_nnm, run_nnm),
    _command("ssm", arguments_ssm, run_ssm),
    _command("driven", arguments_driven, run_driven, notes=True),
    _command("response", arguments_response, run_response, notes=True),
    _command("subharmonic", arguments_subharmonic, run_subharmonic, notes=True),
    _command("parametric", arguments_parametric, run_parametric),
    _command("mixing", arguments_mixing, run_mixing, notes=True),
    _command("choose", arguments_choose, run_choose),
    _command("sweep", arguments_sweep, run_sweep, notes=True),
    _command("clock", arguments_clock, run_clock),
    _command("scene", arguments_scene, run_scene),
    _command("slowflow", arguments_slowflow, run_slowflow,
             Route("resonant flow", _coordinates, run_resonant_modes,
                   ROUTE_COSTS["slowflow resonant flow"])),
    _command("demo", arguments_demo, run_demo),
)
COMMAND = {c.name: c for c in COMMANDS}


def build_parser() -> argparse.ArgumentParser:
    """The parser: one subparser per :data:`COMMANDS` entry, in its order."""
    parser = _Parser(
        prog="lindstedt",
        description="Exact Lindstedt–Poincaré series for nonlinear oscillators, "
        "emitted as numba evaluators and LaTeX.",
    )
    parser.add_argument("--version", action="version", version=f"lindstedt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        command.arguments(sub)
    return parser


def check_cost(route: Route, args: argparse.Namespace) -> None:
    """The method's estimate (lindstedt.costs) before it runs: bounds that no switch lifts,
    then a refusal above COST_LIMIT_SECONDS without --allow-slow, and above
    SLOW_LIMIT_SECONDS with it."""
    if route.cost is None:
        return
    cost = route.cost(args)
    if cost.seconds > SLOW_LIMIT_SECONDS or (
            cost.seconds > COST_LIMIT_SECONDS and not getattr(args, "allow_slow", False)):
        raise InputError(cost.refusal())


def _terminate_as_interrupt() -> Callable[[], None]:
    """SIGTERM raises KeyboardInterrupt in the main thread, as Ctrl-C does (one way to stop a
    command, whichever signal); returns what puts the former handler back."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, interrupt)
    return lambda: signal.signal(signal.SIGTERM, old)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``lindstedt`` command line on ``argv`` (default: ``sys.argv[1:]``): parse,
    check the command's cost estimate, run it.  Returns the exit status: the command's;
    2 for bad input, with one line on stderr (argument errors exit with 2 at once); 1 when
    stdout's reader closed the pipe."""
    parser = build_parser()
    args = parser.parse_args(argv)
    terminated = _terminate_as_interrupt()
    try:
        route = COMMAND[args.command].route(args)
        check_cost(route, args)
        status = route.run(args)
        sys.stdout.flush()  # a reader that went away (`| head`) is noticed here, not at exit
        return status
    except InputError as exc:
        print(f"lindstedt: error: {clipped(str(exc))}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, Interrupted) as exc:
        # Ctrl-C or SIGTERM: one line and exit 130 (128 + SIGINT), at once.  Files are written
        # to temporaries and renamed (emit.write_files), a sweep's blocks with their flags
        # (sweep.store): what stopped midway is not left half-written.  After a sweep (its
        # workers already stopped) os._exit skips the interpreter's exit handlers, which would
        # close its dask cluster in an orderly way: seconds, and log lines.
        what = str(exc) if isinstance(exc, Interrupted) else (
            "stopped before the end; no file is left half-written")
        sys.stdout.flush()
        print(f"lindstedt: interrupted: {what}", file=sys.stderr, flush=True)
        if isinstance(exc, Interrupted):
            os._exit(130)
        return 130
    except BrokenPipeError:
        # The Python docs' recipe (signal module, "Note on SIGPIPE"): stdout's reader closed
        # the pipe; point stdout at devnull so the interpreter's final flush cannot fail
        # again, and exit 1 as Python does on EPIPE.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    finally:
        terminated()


def run() -> NoReturn:
    """The process's entry point (the ``lindstedt`` script, ``python -m lindstedt``):
    :func:`main`'s status as the exit status.  An interrupted command leaves by ``os._exit``
    once its line is out: nothing of the interpreter's shutdown (exit handlers, threads joined,
    the flag CPython keeps of a KeyboardInterrupt raised inside ``exec``'d code) can turn 130
    into a death by SIGINT."""
    status = main()
    if status == 130:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(130)
    sys.exit(status)
