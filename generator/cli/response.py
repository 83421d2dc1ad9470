"""``response``: the periodic response of a driven, damped oscillator of any number of
coordinates over the drive frequency (eq. 10.60 by its flags or its preset's name, an
EQUATION or a SYSTEM): its arguments, its one JSON contract, its table and its CSV, each a
pure function of the one record (:class:`analysis.systems.Response`)."""

from __future__ import annotations

import argparse
import json
import math
import textwrap
from pathlib import Path

from ..errors import InputError
from ..limits import COST_LIMIT_SECONDS
from .common import (
    _charts,
    _flag_allow_slow,
    _flag_csv,
    _flag_drive,
    _flag_equation,
    _flag_harmonics,
    _flag_json,
    _flag_omega,
    _flag_plot,
    _flag_range_bounds,
    _params,
    _quality,
    check_outputs,
    dynamics_json,
    dynamics_lines,
    interval,
    write_csv,
)

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .driven import DRIVE_FLAGS


def response_json(r) -> dict:
    """The contract of ``lindstedt response … --json``, a pure function of a
    :class:`analysis.systems.Response` (any number of coordinates): each traced branch (ω,
    every coordinate's first-harmonic amplitude, the largest Floquet |λ|, stable or not), the
    folds, the bifurcations and attractors, how the branches were searched; a system's
    sweep jumps checked at each fold and its points shot as true orbits (``jumps``,
    ``checks``), its drive as lowered (M⁻¹F) and as written; one equation's force table and
    its folds three ways (one harmonic, the continued N-harmonic balance, the true orbit's
    with its Floquet moduli), the sweeps' jumps and escapes; eq. 10.60's ``parameters`` also
    hold ``eps``, ``force`` and ``Q`` as numbers."""
    names = list(r.coordinates)
    system, de = r.system, r.equation
    branches = []
    for k, piece in enumerate(r.cont.piece_slices()):
        branches.append({
            "closed": r.closed[k],
            "omega": [float(w) for w in r.cont.omega[piece]],
            "amplitudes": {name: [float(a) for a in r.amplitudes[piece, i]]
                           for i, name in enumerate(names)},
            "multiplier": [float(m) for m in r.multiplier[piece]],
            "stable": [bool(s) for s in r.stable[piece]],
        })
    lo, hi = r.omega_range
    data: dict = {
        "kind": "response", "system": system.text if system is not None else de.text,
        "coordinates": names,
        "parameters": {
            "frequency": str(system.frequency) if system is not None else de.frequency,
            "omega_range": [lo, hi],
            "linear_frequencies": list(r.linear_frequencies),
            "harmonics": r.harmonics,
        },
        "branches": branches,
        "folds": [float(w) for w in r.cont.folds],
        "completeness": {"complete": r.complete, "bound": r.bound, "how": r.note,
                         "about": "period-1 orbits",
                         "note": None if r.dynamics is None else r.dynamics.note},
        **({} if r.dynamics is None else dynamics_json(r.dynamics, names)),
        "amplitude": "r_i = sqrt(A_i1^2 + B_i1^2), the first harmonic of coordinate i",
    }
    if system is not None:
        data["parameters"]["drive"] = {name: str(d) for name, d in zip(names, system.drive,
                                                                         strict=True)}
        data["parameters"]["drive_written"] = {name: str(d) for name, d in zip(
            names, system.written_drive, strict=True)}
        data["jumps"] = [_jump_json(r, j, names) for j in r.sweep_jumps]
        data["checks"] = [{"omega": c.omega, "branch": c.piece,
                           "balance": dict(zip(names, c.balance, strict=True)),
                           "shot": dict(zip(names, c.shot, strict=False)),
                           "error": None if c.error != c.error else c.error,
                           "multipliers": [abs(m) for m in c.multipliers],
                           "multipliers_complex": [[m.real, m.imag] for m in c.multipliers],
                           "stable": c.stable, "balance_stable": c.balance_stable,
                           "note": c.note} for c in r.checks]
    if de is not None:
        up, down = r.sweeps
        true_folds = [(w, list(m)) for w, m in r.true_folds]
        data["parameters"] = {**dict(r.notes), **data["parameters"],
                              "values": dict(de.values),
                              "linear_frequency": r.linear_frequencies[0],
                              "drive": {"amplitude": de.force, "frequency": de.frequency}}
        data.update({
            "equation": de.text, "name": de.name,
            "force": [{"q": a, "dq": b, "c": c} for (a, b), c in sorted(de.terms.items())],
            "odd": de.odd,
            "one_harmonic": {"folds": [float(w) for w in r.one_harmonic_folds]},
            "harmonic_balance": {"harmonics": r.harmonics,
                                 "folds": [float(w) for w in r.cont.folds],
                                 "complete": r.cont.complete, "about": "period-1 orbits"},
            "numerical": {"folds": [w for w, _ in true_folds],
                          "fold_floquet_moduli": [m for _, m in true_folds],
                          "sweep_up_jump": up.jump, "sweep_down_jump": down.jump,
                          "sweep_resolution": up.resolution, "sweep_up_escape": up.escape,
                          "sweep_down_escape": down.escape,
                          "escape_bound": r.barrier if math.isfinite(r.barrier) else None},
        })
    return data


def _jump_json(r, j, names: list[str]) -> dict:
    """One jump of a slow sweep (:class:`analysis.systems.SweepJump`) as data."""
    return {"sweep": j.way, "omega": j.omega,
            "from": dict(zip(names, j.leaving, strict=True)),
            "to": dict(zip(names, j.landing, strict=True)),
            "at_fold": j.at_fold, "landing_converged": j.landing_converged,
            "landing_multiplier": j.landing_multiplier,
            "simulated": {n: None if a != a else a
                          for n, a in zip(names, j.simulated, strict=True)},
            "simulation_difference": None if j.difference != j.difference else j.difference,
            "nearest_points": {
                "from": {"omega": float(r.cont.omega[j.before]),
                         **{n: float(r.amplitudes[j.before, i]) for i, n in enumerate(names)}},
                "to": {"omega": float(r.cont.omega[j.after]),
                       **{n: float(r.amplitudes[j.after, i]) for i, n in enumerate(names)}}}}


def _jump_check(j: dict) -> str:
    """How a jump of ``response --json`` was computed and checked, in words."""
    where = ("both at the fold" if j.get("at_fold") else "where the stretch loses stability")
    if not j.get("landing_converged", True):
        where += "; landing: the nearest point (Newton did not converge)"
    diff = j.get("simulation_difference")
    check = ("DOP853 from the fold state did not settle" if diff is None else
             f"DOP853 from the fold state lands within {diff:.1e}" if diff <= 1e-3 else
             f"warning: DOP853 from the fold state settles {diff:.2g} away")
    return f" ({where}; {check})"


def response_table(data: dict) -> list[str]:
    """The table of ``response``, from its JSON: the problem and its range, each branch, the
    folds (one equation: three ways), the sweeps (one equation: simulated; a system: the
    jumps at the folds), the shots, the bifurcations and how the branches were sought."""
    p = data["parameters"]
    names = data["coordinates"]
    lo, hi = p["omega_range"]
    if "equation" in data:
        given = ", ".join(f"{k} = {v}" for k, v in p["values"].items())
        lines = [f"{data['equation']}: {given}{'; ' if given else ''}{p['frequency']} in "
                 f"{interval(lo, hi)} (omega0 = {p['linear_frequency']:.6g})"]
    else:
        drive = ", ".join(f"{k}: {v}" for k, v in p["drive_written"].items() if v != "0")
        lines = [f"response of {data['system']}",
                 f"  {p['frequency']} in {interval(lo, hi)}; linear omega0 = "
                 + ", ".join(f"{w:.6g}" for w in p["linear_frequencies"])
                 + f"; drive amplitude (as written) {drive}; balance of {p['harmonics']} "
                 "harmonics"]
    for k, b in enumerate(data["branches"], 1):
        stable = sum(b["stable"])
        peak = ", ".join(f"{n} {max(b['amplitudes'][n]):.4g}" for n in names)
        kind = "closed (an isola)" if b["closed"] else f"w {b['omega'][0]:.4g} -> " \
            f"{b['omega'][-1]:.4g}"
        lines.append(f"  branch {k}: {kind}, {len(b['omega'])} points, largest r: {peak}; "
                     f"{stable} of {len(b['stable'])} points stable")
    if "numerical" in data:
        num = data["numerical"]
        for label, folds in (("one harmonic", data["one_harmonic"]["folds"]),
                             (f"harmonic balance N={p['harmonics']}", data["folds"]),
                             ("true orbit (Floquet +1)", num["folds"])):
            lines.append(f"{label:>26}: folds "
                         + (", ".join(f"{w:.12f}" for w in folds) or "none"))
        for way in ("up", "down"):
            value, escape = num[f"sweep_{way}_jump"], num[f"sweep_{way}_escape"]
            if escape is not None and "eps" in p:
                text = (f"escapes the well at {escape:.4f} (over the barrier |q| = "
                        f"{num['escape_bound']:.3g}: no steady state beyond)")
            elif escape is not None:
                text = (f"escapes at {escape:.4f} (|q| past {num['escape_bound']:.3g}, 10 "
                        "times every balance solution's: no steady state beyond)")
            elif value is not None:
                text = (f"jumps at {value:.4f} (sweep step {num['sweep_resolution']:.1e} per "
                        "period)")
            else:
                text = "no jump"
            lines.append(f"{'sweep ' + way:>26}: {text}")
    else:
        lines.append("  folds: " + (", ".join(f"{w:.8f}" for w in data["folds"]) or "none"))
    for way in ("up", "down") if "jumps" in data else ():
        jumps = [j for j in data["jumps"] if j["sweep"] == way]
        lines.append(f"  sweep {way}:" + (" no jump" if not jumps else ""))
        lines += [f"    jumps at {j['omega']:.6f}: " + ", ".join(
            f"{n} {j['from'][n]:.4g} -> {j['to'][n]:.4g}" for n in names) + _jump_check(j)
            for j in jumps]
    checks = data.get("checks", [])
    shot = [c for c in checks if c["error"] is not None]
    agree = sum(c["stable"] == c["balance_stable"] for c in shot)
    if checks:
        lines.append(f"  shooting (DOP853): {len(shot)} of {len(checks)} points converged, "
                     "largest harmonic difference "
                     + (f"{max(c['error'] for c in shot):.1e}" if shot else "-")
                     + f", stability agrees at {agree} of {len(shot)}")
    for c in checks:
        if c["error"] is None:
            lines.append(f"    w = {c['omega']:.6g}: not shot ({c['note']})")
    lines += dynamics_lines(data) if "bifurcations" in data else []
    done = data["completeness"]
    lines += textwrap.wrap(("search for period-1 orbits: " if done["complete"] else
                            "warning: the search for period-1 orbits may be incomplete: ")
                           + done["how"], 96, initial_indent="  ", subsequent_indent="    ")
    if done.get("note"):
        lines += textwrap.wrap(done["note"], 96, initial_indent="  ",
                               subsequent_indent="    ")
    return lines


def response_csv(r, path: Path) -> Path:
    """``response --csv``: every point of every branch, as drawn and in the JSON: ω, each
    coordinate's first-harmonic amplitude (``r`` for one equation, ``r_<x>`` for a system's
    coordinate x), the largest Floquet modulus, stable or not."""
    names = list(r.coordinates)
    columns = (("branch", "piece of the continued balance from 1"),
               ("omega", "drive frequency"),
               *((("r", "first harmonic sqrt(A1^2 + B1^2)"),) if len(names) == 1 else
                 ((f"r_{n}", f"first harmonic of {n}") for n in names)),
               ("multiplier", "largest Floquet modulus"), ("stable", "1 if stable"))
    rows = ((k, r.cont.omega[i], *r.amplitudes[i], r.multiplier[i], bool(r.stable[i]))
            for k, piece in enumerate(r.cont.piece_slices(), 1)
            for i in range(len(r.cont.omega))[piece])
    return write_csv(path, columns, rows)


def _response_args(args: argparse.Namespace) -> None:
    """The flags of ``response`` with and without EQUATION, each refused in one line where it
    does not belong: the notes' flags go with no problem or with its preset's name."""
    if args.model is not None:
        given = [f"--{k}" for k in DRIVE_FLAGS if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)}: with an equation give its parameters with "
                             "--param (e.g. --param eps=1/10) and the drive in the equation")
        return
    if args.param or args.name:
        raise InputError("--param/--name: give an equation (EQUATION) to take them")
    missing = [f"--{k}" for k in DRIVE_FLAGS if getattr(args, k) is None]
    if missing:
        raise InputError(f"the following arguments are required: {', '.join(missing)}")


def response_report(args: argparse.Namespace, limit: float):
    """The one computation of ``response`` (eq. 10.60 or an EQUATION): its
    :class:`analysis.systems.Response`, which the JSON, the table, the figure and the CSV
    print (eq. 10.60 by its flags, without a problem or with its preset's name)."""
    from ..analysis.systems import driven_problem, notes_problem, response

    if args.model is not None:
        return response(driven_problem(args.model, _params(args.param),
                                       args.name or "oscillator"), args.harmonics,
                        args.omega_min, args.omega_max, limit)
    de, closed = notes_problem(args.eps, args.force, args.Q)
    return response(de, args.harmonics, args.omega_min, args.omega_max, limit, closed)


def run_response(args: argparse.Namespace) -> int:
    """Run ``lindstedt response`` (eq. 10.60 by its flags, with or without its preset's
    name, an EQUATION or a SYSTEM): the response curve over ω, computed once, as a table,
    JSON, a figure or CSV.  Returns the exit status."""
    _response_args(args)
    limit = math.inf if args.allow_slow else COST_LIMIT_SECONDS
    plot, csv = check_outputs(args)
    r = response_report(args, limit)
    if plot is not None:
        _charts().response_figure(r, plot)
    if csv is not None:
        response_csv(r, csv)
    data = response_json(r)
    print(json.dumps(data) if args.json else "\n".join(response_table(data)))
    return 0


def arguments_response(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt response``'s arguments."""
    p = sub.add_parser("response", help="folds and hysteresis of the damped driven oscillator",
                       description="Response curve over ω: folds three ways, sweep jumps. "
                       "q'' + q'/Q + q + eps q^3 = f cos(w t) (--eps, --force, --Q, with or "
                       "without its preset's name duffing), or your "
                       "own damped equation q'' + g(q, q') = f*cos(w*t), g a polynomial, with "
                       "--param for every parameter but w; or a SYSTEM of coupled damped "
                       "oscillators, one equation per coordinate separated by ';', driven by "
                       "f*cos(w*t) on one or more of them: every branch (a bound on the "
                       "amplitude says none is missed), Floquet stability, folds, sweep jumps, "
                       "each branch checked by shooting.")
    _flag_equation(p, "\"q'' + 0.05*q' + q + eps*(q**2 + q**3) = f*cos(w*t)\" (a "
                   "polynomial force with damping, one drive f*cos(w*t) whose w the curve "
                   "varies), or a system \"x1'' + 0.05*x1' + 2*x1 - x2 + x1**3/2 = "
                   "f*cos(w*t); x2'' + 0.05*x2' + 2*x2 - x1 = 0\"",
                   "Duffing's q'' + q'/Q + q + εq³ = f cos ωt with --eps, --force, "
                   "--Q", "every parameter but w "
                   "needs one")
    _flag_drive(p, required=False, omega=None, Q=None, notes=True)
    p.add_argument("--Q", type=_quality, default=None, metavar="Q",
                   help="quality factor Q > 0 of the damping q'/Q (finite; required without "
                   "EQUATION)")
    _flag_omega(p, ("A:B",), "the drive frequencies ω of the curve, from A to B, in units "
                "of the linear natural frequency ω0 (default: from half the lowest of ω0 and "
                "the one-harmonic folds to 1.25 × the highest); with a SYSTEM: in its own "
                "time units (default: half the lowest linear ω0 to 1.5 × the highest)")
    _flag_range_bounds(p, "--omega-min", "--omega-max")
    _flag_harmonics(p, "odd harmonics N of the continued balance (with EQUATION: harmonics "
                    "1..2N-1, with the constant and even ones unless the force is odd)")
    _flag_json(p)
    _flag_plot(p)
    _flag_csv(p, "the branches of the continued balance (branch, omega, r; a SYSTEM: each "
              "coordinate's r, the largest Floquet modulus, stable)")
    _flag_allow_slow(p, deprecated_force=False)
    return p
