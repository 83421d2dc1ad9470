"""The ``lindstedt`` command line.  Bad input: one line on stderr, exit status 2.

One module per command family (:mod:`.series`, :mod:`.system`, :mod:`.driven`,
:mod:`.choose`, :mod:`.sweep`, :mod:`.demo`), each with its commands' arguments, JSON contracts
and tables;
:data:`COMMANDS` here lists them for the parser, the cost guard and ``--help``."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NoReturn

from .. import __version__
from ..costs import COSTS
from ..errors import InputError, Interrupted
from ..limits import COST_LIMIT_SECONDS
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
    arguments_response,
    arguments_subharmonic,
    run_driven,
    run_mixing,
    run_parametric,
    run_response,
    run_subharmonic,
)
from .series import (
    arguments_generate,
    arguments_mathieu,
    arguments_models,
    arguments_series,
    arguments_slowflow,
    arguments_tongues,
    run_generate,
    run_mathieu,
    run_models,
    run_series,
    run_slowflow,
    run_tongues,
)
from .sweep import arguments_sweep, run_sweep
from .system import arguments_nnm, run_nnm


@dataclass(frozen=True)
class Command:
    """One command: its name, the function that adds its arguments (a subparser), the one that
    runs it, and its cost estimate (:data:`costs.COSTS`, checked before it runs; ``None``: a
    command too quick to estimate).  The parser, the cost guard and ``--help`` loop over
    :data:`COMMANDS`."""

    name: str
    arguments: Callable[[argparse._SubParsersAction], argparse.ArgumentParser]
    run: Callable[[argparse.Namespace], int]
    cost: Callable[[argparse.Namespace], object] | None


COMMANDS: tuple[Command, ...] = tuple(
    Command(name, arguments, run, COSTS.get(name)) for name, arguments, run in (
    ("series", arguments_series, run_series),
    ("mathieu", arguments_mathieu, run_mathieu),
    ("tongues", arguments_tongues, run_tongues),
    ("models", arguments_models, run_models),
    ("generate", arguments_generate, run_generate),
    ("nnm", arguments_nnm, run_nnm),
    ("driven", arguments_driven, run_driven),
    ("response", arguments_response, run_response),
    ("subharmonic", arguments_subharmonic, run_subharmonic),
    ("parametric", arguments_parametric, run_parametric),
    ("mixing", arguments_mixing, run_mixing),
    ("choose", arguments_choose, run_choose),
    ("sweep", arguments_sweep, run_sweep),
    ("clock", arguments_clock, run_clock),
    ("scene", arguments_scene, run_scene),
    ("slowflow", arguments_slowflow, run_slowflow),
    ("demo", arguments_demo, run_demo),
))
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
        command.arguments(sub).set_defaults(func=command.run)
    return parser


def check_cost(args: argparse.Namespace) -> None:
    """Every command's estimate (lindstedt.costs.COSTS) before it runs: bounds that no switch
    lifts, then a refusal above COST_LIMIT_SECONDS without --allow-slow."""
    estimate = COMMAND[args.command].cost
    if estimate is None:
        return
    cost = estimate(args)
    if cost.seconds > COST_LIMIT_SECONDS and not getattr(args, "allow_slow", False):
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
        check_cost(args)
        status = args.func(args)
        sys.stdout.flush()  # a reader that went away (`| head`) is noticed here, not at exit
        return status
    except InputError as exc:
        print(f"lindstedt: error: {exc}", file=sys.stderr)
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
