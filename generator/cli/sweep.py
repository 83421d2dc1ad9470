"""``sweep``: maps over the notes' axes or any parameters of an equation or a system (``sweep
ssm SYSTEM``: one mode's spectral submanifold and its forced response at each point)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
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
from .ssm import DEFAULT_ORDER, _order

KINDS_HERE = tuple(dict.fromkeys((*SWEEP_KINDS, "ssm")))
# NOTE: sweep.KINDS's keys (common.SWEEP_KINDS, with ssm until it lists it).


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
    ssm = args.kind == "ssm"
    if not ssm and (args.mode is not None or args.order is not None):
        raise InputError(f"--mode/--order: sweep ssm's (the SSM's mode and order), not sweep "
                         f"{args.kind}'s")
    if ssm and args.model is None:
        kind_of(args.kind)  # refused: ssm maps a system
    if args.model is not None:
        grid = _frc_grid(builtin.pop("omega")) if ssm and "omega" in builtin else None
        if builtin:
            raise InputError(f"{', '.join('--' + k for k in builtin)}: with an equation give "
                             "its axes with --axis NAME=A:B:N and its values with --param")
        axes = dict(args.axis or [])
        if len(axes) != len(args.axis or []):
            raise InputError("--axis: each parameter once")
        more = {} if not ssm else {
            "mode": 1 if args.mode is None else args.mode,
            "order": DEFAULT_ORDER if args.order is None else args.order, "omega": grid}
        kind = kind_of(args.kind, args.model, _params(args.param), list(axes),
                       3 if args.n is None else args.n, args.name or "oscillator", **more)
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
    if ssm:  # its refused points: folds −1 (store.summary reads an orbits map's "orbits")
        found = summary(ds.rename({"folds": "orbits"}))
        held = replace(held, refused=found.refused, first_refused=found.first_refused)
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
        points = math.prod(map(len, data["axes"].values()))
        if ssm:
            print(f"  note: {held.refused} of {points} points hold no forced response (folds "
                  f"= -1): the SSM or its forced response is refused there, first at {where} "
                  "(lindstedt ssm SYSTEM at that point says why)")
        else:
            print(f"  note: {held.refused} of {points} points hold no orbit (orbits = -1): "
                  f"the equation is refused there, first at {where} (lindstedt response "
                  "EQUATION at that point says why)")
    if args.plot:
        print(f"  figure {args.plot}")
    return 0


def _frc_grid(values: list[float]) -> tuple[float, float, int]:
    """``sweep ssm``'s ``--omega A:B:N`` (parsed by :func:`_axis_values`) as ``(A, B, N)``:
    N ≥ 2 drive frequencies evenly spaced from A to B, each point's forced response."""
    n = len(values)
    lo, hi = values[0], values[-1]
    if n < 2 or any(abs(v - (lo + (hi - lo) * i / (n - 1))) > 1e-9 * abs(hi - lo)
                    for i, v in enumerate(values)):
        raise InputError("--omega: sweep ssm takes A:B:N, N >= 2 drive frequencies evenly "
                         "spaced from A to B (each point's forced response)")
    return lo, hi, n


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
                       "all four, subharmonic omega, force and eps). sweep ssm SYSTEM: the "
                       "spectral submanifold of --mode M to --order K at each point and its "
                       "forced response over --omega A:B:N; any parameter but the drive "
                       "frequency an --axis (one SSM per distinct M, C, K and f: an axis of the "
                       "drive alone reuses it).")
    p.add_argument("kind", choices=KINDS_HERE,
                   help="response: r of every branch; stability: Floquet verdicts of the true "
                   "orbits (with an EQUATION both: every orbit shot, r and its verdict); "
                   "subharmonic: orbits of n drive periods (without EQUATION: Duffing's 1/3 "
                   "subharmonic); validity: the μ-expansion's error (Duffing's only); ssm "
                   "(a SYSTEM or an EQUATION only): one mode's spectral submanifold at each "
                   "point, its forced response's peak of each coordinate (peak_<x>), the ω and "
                   "ρ of its largest state, its folds, the linear ω0 and damping ratio, the "
                   "first normal-form coefficient gamma_1")
    p.add_argument("model", metavar="EQUATION", nargs="?", default=None,
                   help="a driven equation such as \"q'' + 0.05*q' + q + eps*(alpha*q**2 + "
                   "q**3) = f*cos(w*t)\", or a SYSTEM of them separated by ';' (response: "
                   "every coordinate's r; ssm: one mode's SSM); default: Duffing's "
                   "q'' + q'/Q + q + εq³ = f cos ωt with --omega, --force, --eps, --Q")
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
    p.add_argument("--mode", type=_positive, default=None, metavar="M",
                   help="sweep ssm: the mode, numbered 1, 2, … by increasing damped frequency "
                   "(default 1)")
    p.add_argument("--order", type=_order, default=None, metavar="K",
                   help=f"sweep ssm: the SSM's order K (default {DEFAULT_ORDER})")
    for name, meaning in (("omega", "ω, drive frequency (subharmonic: its own, drive at 3ω)"),
                          ("force", "f, drive amplitude"), ("eps", "ε, cubic stiffness"),
                          ("Q", "quality factor (inf: undamped)")):
        also = ("; sweep ssm SYSTEM: the drive frequencies of each point's forced response, "
                "A:B:N (default ±20 %% about the mode's linear frequency, 500 of them)"
                if name == "omega" else "")
        p.add_argument(f"--{name}", type=_axis_values, metavar="VALUES",
                       help=f"without EQUATION: {meaning}: A:B:N, v1,v2,… or one value{also}")
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
