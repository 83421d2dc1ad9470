"""``sweep``: maps over the notes' axes or any parameters of an equation."""

from __future__ import annotations

import argparse
import json
import math
import sys
from fractions import Fraction
from pathlib import Path

from ..errors import InputError
from ..limits import SWEEP_MAX_VALUES
from ..sweep.cores import usable_cores

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    SWEEP_KINDS,
    ProgressBar,
    _flag_allow_slow,
    _flag_json,
    _flag_out,
    _flag_plot,
    _out_folder,
    _params,
    _positive,
)


def run_sweep(args: argparse.Namespace) -> int:
    """A map over a parameter grid on dask.distributed, into a resumable Zarr store."""
    if args.out is None:
        raise InputError("the following arguments are required: --out")
    if args.plot:
        from ..charts import check_plot_path

        check_plot_path(Path(args.plot))
    from ..sweep.kinds import kind_of
    from ..sweep.store import run_sweep, summary

    builtin = {name: getattr(args, name) for name in ("omega", "force", "eps", "Q")
               if getattr(args, name) is not None}
    kind: object = args.kind
    if args.model is not None:
        if builtin:
            raise InputError(f"{', '.join('--' + k for k in builtin)}: with an equation give "
                             "its axes with --axis NAME=A:B:N and its values with --param")
        axes = dict(args.axis or [])
        if len(axes) != len(args.axis or []):
            raise InputError("--axis: each parameter once")
        kind = kind_of(args.kind, args.model, _params(args.param), list(axes),
                             3 if args.n is None else args.n, args.name or "oscillator")
    else:
        if args.axis or args.param or args.name or args.n is not None:
            raise InputError("--axis/--param/--name/--n: give an equation (EQUATION) to take "
                             "them; Duffing's map takes --omega, --force, --eps, --Q")
        axes = builtin
    asked = getattr(args, "workers_asked", None)
    if args.scheduler is None and asked is not None and asked > args.workers:
        print(f"lindstedt: note: --workers {asked}: {usable_cores()} cores here; running "
              f"{args.workers} workers", file=sys.stderr)
    bar = ProgressBar(f"sweep {args.kind}", not args.json)
    try:
        ds = run_sweep(kind, axes, _out_folder(args.out, "--out"), args.scheduler,
                       args.workers, args.chunk, lambda p: bar(p.finished, p.total))
    finally:
        bar.close()  # an interrupt's line starts on a clean line
    if args.plot:
        from ..charts import sweep_figure

        sweep_figure(ds, Path(args.plot))
    held = summary(ds)
    data = {"kind": args.kind, "store": str(args.out),
            "axes": {name: list(values) for name, values in held.axes},
            "fields": list(held.fields), "blocks": held.blocks, "finished": held.finished,
            "complete": held.complete, "refused_points": held.refused}
    if args.model is not None:
        data["equation"] = args.model
    if args.plot:
        data["plot"] = args.plot
    if args.json:
        print(json.dumps(data))
        return 0
    shape = " × ".join(f"{len(v)} {k}" for k, v in data["axes"].items())
    print(f"sweep {args.kind}: {shape} into {args.out}: {data['finished']}/{data['blocks']} "
          f"blocks done; fields {', '.join(data['fields'])}")
    if held.refused:
        where = ", ".join(f"{k} = {v:g}" for k, v in held.first_refused)
        print(f"  note: {held.refused} of {math.prod(map(len, data['axes'].values()))} points "
              f"hold no orbit (orbits = -1): the equation is refused there, first at {where} "
              f"(lindstedt response EQUATION at that point says why)")
    if args.plot:
        print(f"  figure {args.plot}")
    return 0


def _axis_values(text: str) -> list[float]:
    """Axis values: ``A:B:N`` (N evenly spaced from A to B), ``v1,v2,…`` or one value; each
    a decimal or a fraction ``p/q``."""

    def number(v: str) -> float:
        return float(Fraction(v.strip())) if "/" in v else float(v)

    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if not 1 <= n <= SWEEP_MAX_VALUES:
                raise argparse.ArgumentTypeError(f"{text!r}: N must be 1..{SWEEP_MAX_VALUES}")
            a, b = number(start), number(stop)
            values = [a + (b - a) * i / (n - 1) for i in range(n)] if n > 1 else [a]
        else:
            values = [number(v) for v in text.split(",")]
    except (ValueError, ZeroDivisionError):
        raise argparse.ArgumentTypeError(f"{text!r}: expected A:B:N, v1,v2,… or a number"
                                         ) from None
    if any(math.isnan(v) for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: not a number")
    return values


def _named_axis(text: str) -> tuple[str, list[float]]:
    """``NAME=VALUES`` of ``--axis`` (:func:`_axis_values`)."""
    name, sep, values = text.partition("=")
    if not sep or not name.strip().isidentifier():
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME=A:B:N, NAME=v1,v2,… or "
                                         "NAME=value")
    return name.strip(), _axis_values(values)


class _Workers(argparse.Action):
    """``--workers N``: at most :func:`~lindstedt.sweep.cores.usable_cores` (the cost estimate
    then counts the workers that run); the number asked is kept for the command's note."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: object, option_string: str | None = None) -> None:
        namespace.workers_asked = values
        namespace.workers = min(values, usable_cores())


def arguments_sweep(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt sweep``'s arguments."""
    p = sub.add_parser("sweep", help="maps over parameter grids on a Dask cluster, resumable",
                       description="Map a driven oscillator over a grid of parameters on "
                       "dask.distributed (a LocalCluster here by default), block by block into "
                       "a Zarr store; run the same command again to resume an interrupted "
                       "sweep. Your own equation: any of its parameters (the drive frequency "
                       "included) an --axis, the rest --param; without EQUATION Duffing's "
                       "q'' + q'/Q + q + eps q^3 = f cos(wt) over --omega, --force, --eps, --Q "
                       "(A:B:N is N values from A to B; response, stability and validity take "
                       "all four, subharmonic omega, force and eps).")
    p.add_argument("kind", choices=SWEEP_KINDS,
                   help="response: r of every branch; stability: Floquet verdicts of the true "
                   "orbits (with an EQUATION both: every orbit shot, r and its verdict); "
                   "subharmonic: orbits of n drive periods (without EQUATION: Duffing's 1/3 "
                   "subharmonic); validity: the μ-expansion's error (Duffing's only)")
    p.add_argument("model", metavar="EQUATION", nargs="?", default=None,
                   help="a driven equation such as \"q'' + 0.05*q' + q + eps*(alpha*q**2 + "
                   "q**3) = f*cos(w*t)\", or a SYSTEM of them separated by ';' (response "
                   "only: every coordinate's r); default: Duffing's q'' + q'/Q + q + εq³ = "
                   "f cos ωt with --omega, --force, --eps, --Q")
    p.add_argument("--axis", type=_named_axis, action="append", metavar="NAME=VALUES",
                   help="with EQUATION: a parameter swept, e.g. w=0.8:1.6:41 or alpha=0,1/2,1 "
                   "(A:B:N, v1,v2,… or one value; repeatable; the store's coordinates take "
                   "these names)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="with EQUATION: an exact value for each parameter that is no axis, "
                   "e.g. eps=1/10 (repeatable)")
    p.add_argument("--name", metavar="NAME",
                   help="with EQUATION: the oscillator's name in messages (default: oscillator)")
    p.add_argument("--n", type=_positive, default=None, metavar="N",
                   help="with EQUATION, subharmonic: orbits of N drive periods (default 3)")
    for name, meaning in (("omega", "ω, drive frequency (subharmonic: its own, drive at 3ω)"),
                          ("force", "f, drive amplitude"), ("eps", "ε, cubic stiffness"),
                          ("Q", "quality factor (inf: undamped)")):
        p.add_argument(f"--{name}", type=_axis_values, metavar="VALUES",
                       help=f"without EQUATION: {meaning}: A:B:N, v1,v2,… or one value")
    _flag_out(p, "the Zarr store (a folder) the map is written into, block by block "
              "(required; an existing store of the same sweep resumes)", old="--store")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="tcp://host:port of a running dask scheduler whose workers have "
                   "lindstedt (default: a LocalCluster on this machine)")
    cores = usable_cores()
    p.add_argument("--workers", type=_positive, action=_Workers, default=min(2, cores),
                   metavar="N", help="worker processes of the LocalCluster, one thread each "
                   f"(default 2), at most the cores this process may use ({cores} here): a "
                   "larger N is cut to that, with a note on stderr (more single-threaded "
                   "workers than cores would only share them)")
    p.add_argument("--chunk", type=_positive, default=None, metavar="POINTS",
                   help="grid points per task (default: the kind's, about 1 s of work)")
    _flag_json(p, "a JSON summary")
    _flag_plot(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p
