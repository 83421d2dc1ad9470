"""The driven commands: ``driven``, ``subharmonic``, ``parametric`` and ``mixing``: their
arguments, JSON contracts and tables (``response``: :mod:`.response`)."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from ..errors import InputError
from ..limits import PARAMETRIC_MAX_POINTS

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    _charts,
    _deprecated,
    _equation_args,
    _first_harmonic,
    _flag_allow_slow,
    _flag_drive,
    _flag_equation,
    _flag_harmonics,
    _flag_json,
    _flag_omega,
    _flag_order,
    _flag_plot,
    _flag_range_bounds,
    _keyed,
    _params,
    _positive,
    _quality,
    _real,
    _report,
)


def driven_report_json(report) -> dict:
    """The JSON of a :class:`analysis.periodic.DrivenReport`, a pure function of it: every
    distinct 1:1 orbit, largest first, each three ways where it can be.

    A branch carries the first-order root that stands for it (``seed`` says how the orbit was
    found, ``first_order`` how the root was paired with it); an orbit that no one-harmonic root
    stands for (found by continuing the balance through a fold the cubic does not have) has
    ``A1``, ``r``, ``delta0`` null and no μ-expansion, with ``mu_note`` saying why."""
    from ..analysis.driven import amplitudes
    from ..numerics.floquet import multipliers_stable

    d, order, harmonics, found = report.drive, report.order, report.harmonics, report.found
    damped = d.damping > 0
    branches = []
    for b in report.branches:
        orb = b.orbit
        br, orbit, hb, mu = orb.branch, orb.orbit, orb.balance, b.mu
        orders: list[dict] = []
        if mu is not None:
            for j in range(len(mu.coefficients)):
                c, phase = mu.partial(j)
                A, B = amplitudes(c, phase, 2 * j + 1)
                entry = {"order": j, "A": _keyed(A), "delta": phase, "r": _first_harmonic(A, B)}
                if damped:
                    entry["B"] = _keyed(B)
                orders.append(entry)
            mu_converged, mu_note = mu.converged, mu.reason
        else:
            mu_converged = False
            mu_note = ("no one-harmonic root stands for this orbit (found by continuing the "
                       "harmonic balance through a fold the one-harmonic cubic does not have "
                       "at this omega): no first-order data, no mu-expansion")
        if hb is not None:
            A, B = b.balance_amplitudes
            hb_json = {"harmonics": harmonics, "A": _keyed(A), "residual": hb.residual,
                       "converged": hb.converged, "r": _first_harmonic(A, B)}
            if damped:
                hb_json["B"] = _keyed(B)
            hb_json["full_hill_stable"] = multipliers_stable(b.full_hill, damped)
            hb_json["full_hill_moduli"] = sorted(float(abs(m)) for m in b.full_hill)
        else:
            hb_json = {"harmonics": harmonics, "A": {}, "residual": None, "converged": False,
                       "r": None}
        numerical = None
        if orbit is not None:
            numerical = {"A": _keyed(orbit.A), "floquet_moduli": sorted(
                float(abs(m)) for m in orbit.multipliers), "stable": orbit.stable,
                "r": _first_harmonic(orbit.A, orbit.B),
                "initial": [float(v) for v in orbit.initial]}
            if damped:
                numerical["B"] = _keyed(orbit.B)
        branches.append({
            "A1": None if br is None else br.A1, "r": None if br is None else abs(br.A1),
            "delta0": None if br is None else br.delta0, "seed": orb.seed,
            "first_order": orb.paired, "mu_expansion": orders,
            "mu_converged": mu_converged, "mu_note": mu_note,
            "harmonic_balance": hb_json, "numerical": numerical,
            **_shooting_json(orb.failure),
        })
    failures = found.failures or (None,) * len(found.roots)
    roots = [{"A1": br.A1, "r": abs(br.A1), "delta0": br.delta0, "branch": j,
              **_shooting_json(why)} for (br, j), why in zip(found.roots, failures, strict=True)]
    return {
        "parameters": {"eps": d.eps, "force": d.force, "omega": d.omega,
                       "Q": None if math.isinf(d.Q) else d.Q, "order": order,
                       "harmonics": harmonics},
        "branches": branches,
        "one_harmonic_roots": roots,
        "seeding": {"complete": found.complete, "note": found.note},
    }


def _shooting_json(failure) -> dict:
    """Why shooting found no orbit (``None`` where it found one); ``escapes``: the trajectory
    from the seed left the well (a softening spring: it runs off to infinity)."""
    return {"escapes": bool(failure is not None and failure.escaped),
            "shooting_note": None if failure is None else failure.reason}


def driven_table(data: dict) -> str:
    """The text table of ``driven`` (eq. 10.60), from its JSON: each orbit three ways, the
    one-harmonic roots that stand for none."""
    p = data["parameters"]
    lines = [f"q'' + q'/Q + q + eps q^3 = f cos(w t): eps = {p['eps']}, f = {p['force']}, "
             f"w = {p['omega']}, Q = {p['Q'] if p['Q'] is not None else 'inf (undamped)'}"]
    damped = p["Q"] is not None
    columns = ("r", "A1", "B1", "A3", "A5") if damped else ("A1", "A3", "A5")
    for i, br in enumerate(data["branches"], 1):
        num = br["numerical"]
        verdict = (("escapes the well" if br.get("escapes") else "no orbit found") if num is None
                   else "stable" if num["stable"] else "unstable")
        if br["A1"] is None:
            found = (f"true r = {num['r']:.6f}, " if num is not None else "") + \
                "found by continuation, no one-harmonic root"
            lines.append(f"\nbranch {i}: {found} ({verdict})")
        else:
            first = (f"r = {br['r']:.6f}, phase delta0 = {br['delta0']:.6f}" if damped
                     else f"A1 = {br['A1']:.6f}")
            lines.append(f"\nbranch {i}: first-order {first} ({verdict})")
        lines.append(f"{'':>22} " + " ".join(f"{c:>12}" for c in columns))
        hb = br["harmonic_balance"]
        rows = [(f"mu-expansion order {e['order']}", e) for e in br["mu_expansion"]]
        rows.append((f"harmonic balance N={hb['harmonics']}", hb))
        if num is not None:
            rows.append(("numerical (shooting)", num))
        for label, row in rows:
            if row is hb and not hb["converged"]:
                why = "" if hb["residual"] is None else f": residual {hb['residual']:.1e}"
                lines.append(f"{label:>22} (did not converge{why})")
                continue
            values = {"r": row["r"], **{f"A{k}": v for k, v in row["A"].items()},
                      **{f"B{k}": v for k, v in row.get("B", {}).items()}}
            cells = " ".join(f"{values[c]:>12.6f}" if c in values else f"{'':>12}"
                             for c in columns)
            lines.append(f"{label:>22} {cells}")
        if "full_hill_stable" in hb:
            lines.append("  full Hill equation about the balance: "
                         f"{'stable' if hb['full_hill_stable'] else 'unstable'} (|multipliers| "
                         + ", ".join(f"{m:.6g}" for m in hb["full_hill_moduli"]) + ")")
        if br.get("first_order") == "rank":
            lines.append("  note: the first-order root of the same rank in amplitude (shooting "
                         "from it reached another orbit)")
        if not br["mu_converged"]:
            lines.append(f"  warning: {br['mu_note']}")
        if num is None and br.get("shooting_note"):
            lines.append(f"  shooting: {br['shooting_note']}")
    for root in data.get("one_harmonic_roots", []):
        if root["branch"] is None:
            first = (f"r = {root['r']:.6f}, phase delta0 = {root['delta0']:.6f}" if damped
                     else f"A1 = {root['A1']:.6f}")
            if root.get("escapes"):
                lines.append(f"\nwarning: the one-harmonic root {first} stands for no orbit: "
                             f"{root['shooting_note']}")
            else:
                lines.append(f"\nwarning: the one-harmonic root {first} stands for no orbit "
                             "found (shooting from it reached none, or one a nearer root "
                             "stands for)")
    seeding = data.get("seeding")
    if damped and seeding is not None and not seeding["complete"]:
        lines.append(f"\nwarning: seeds from the one-harmonic roots only ({seeding['note']}); "
                     "orbits beyond them may be missing")
    return "\n".join(lines)


def driven_equation_report_json(report) -> dict:
    """The JSON of a user's :class:`analysis.periodic.DrivenReport`, a pure function of it: every
    distinct 1:1 orbit found, largest first, each by its harmonic balance (``A`` holds the
    constant ``"0"`` and even harmonics unless the force is odd; the full Hill equation's
    verdict about it where the velocity part of the force is linear) and, checked by shooting,
    the true orbit with its Floquet moduli and verdict."""
    from ..numerics.floquet import multipliers_stable

    de, harmonics, found = report.equation, report.harmonics, report.found
    branches = []
    for b in report.branches:
        orb = b.orbit
        hb = orb.balance
        hb_json = {"harmonics": harmonics, "A": {}, "B": {},
                   "residual": hb.residual if hb is not None and hb.converged else None,
                   "converged": b.balance_amplitudes is not None, "r": None}
        if b.balance_amplitudes is not None:
            A, B = b.balance_amplitudes
            hb_json.update(A=_keyed(A), B=_keyed(B), r=_first_harmonic(A, B))
            if b.full_hill is not None:
                hb_json["full_hill_stable"] = multipliers_stable(b.full_hill, de.dissipative)
                hb_json["full_hill_moduli"] = sorted(float(abs(m)) for m in b.full_hill)
        numerical = None
        if orb.orbit is not None:
            o = orb.orbit
            numerical = {"A": _keyed(o.A), "B": _keyed(o.B), "floquet_moduli": sorted(
                float(abs(m)) for m in o.multipliers), "stable": o.stable,
                "r": _first_harmonic(o.A, o.B), "initial": [float(v) for v in o.initial],
                "residual": o.residual}
        branches.append({
            "r": None if numerical is None else numerical["r"],
            "stable": None if numerical is None else numerical["stable"],
            "harmonic_balance": hb_json, "numerical": numerical,
            **_shooting_json(orb.failure),
        })
    return {
        "equation": de.text,
        "name": de.name,
        "parameters": {"omega": de.omega, "harmonics": harmonics, "values": dict(de.values),
                       "drive": {"amplitude": de.force, "frequency": de.frequency}},
        "force": [{"q": a, "dq": b, "c": c} for (a, b), c in sorted(de.terms.items())],
        "odd": de.odd,
        "branches": branches,
        "seeding": {"complete": found.complete, "note": found.note},
    }


def driven_equation_table(data: dict) -> str:
    """The text table of ``driven EQUATION``, from its JSON: each orbit's balance and shot
    orbit with its Floquet moduli and verdict."""
    p = data["parameters"]
    given = ", ".join(f"{k} = {v}" for k, v in p["values"].items())
    lines = [f"{data['equation']}: {given}{', ' if given else ''}{p['drive']['frequency']} = "
             f"{p['omega']}"]
    orders = ([1, 3, 5] if data["odd"] else [0, 1, 2, 3])
    columns = ["r", *(f"A{k}" for k in orders), *(f"B{k}" for k in orders if k)]
    for i, br in enumerate(data["branches"], 1):
        num = br["numerical"]
        verdict = (("escapes" if br.get("escapes") else "no orbit found") if num is None
                   else "stable" if num["stable"] else "unstable")
        moduli = "" if num is None else ", Floquet |lambda| = " + ", ".join(
            f"{m:.6f}" for m in num["floquet_moduli"])
        lines.append(f"\nbranch {i}: r = {br['r'] if br['r'] is None else round(br['r'], 6)}"
                     f" ({verdict}{moduli})")
        lines.append(f"{'':>22} " + " ".join(f"{c:>11}" for c in columns))
        hb = br["harmonic_balance"]
        rows = [(f"harmonic balance N={hb['harmonics']}", hb)]
        if num is not None:
            rows.append(("numerical (shooting)", num))
        for label, row in rows:
            if row is hb and not hb["converged"]:
                lines.append(f"{label:>22} (did not converge)")
                continue
            values = {"r": row["r"], **{f"A{k}": v for k, v in row["A"].items()},
                      **{f"B{k}": v for k, v in row["B"].items()}}
            lines.append(f"{label:>22} " + " ".join(
                f"{values[c]:>11.6f}" if c in values else f"{'':>11}" for c in columns))
        if num is None and br.get("shooting_note"):
            lines.append(f"  shooting: {br['shooting_note']}")
    seeding = data["seeding"]
    if not seeding["complete"]:
        lines.append(f"\nwarning: {seeding['note']}; orbits beyond it may be missing")
    return "\n".join(lines)


DRIVE_FLAGS = ("eps", "force", "Q")


def run_driven(args: argparse.Namespace) -> int:
    """Run ``lindstedt driven`` (eq. 10.60 or an EQUATION) at one ω, as a table or JSON.
    Returns the exit status."""
    from ..analysis.driven import Drive, check_steady_state

    if args.model is not None:
        given = [f"--{k}" for k in DRIVE_FLAGS if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)}: with an equation give its parameters with "
                             "--param (e.g. --param eps=1/10) and the drive in the equation")
        if args.omega is None:
            raise InputError("--omega: the drive frequency is required")
        from ..analysis.periodic import driven_report
        from ..analysis.polynomial import driven_equation

        de = driven_equation(args.model, _params(args.param), args.omega,
                             args.name or "oscillator")
        data = driven_equation_report_json(driven_report(de, 0, args.harmonics))
        print(json.dumps(data) if args.json else driven_equation_table(data))
        return 0
    if args.param or args.name:
        raise InputError("--param/--name: give an equation (EQUATION) to take them")
    missing = [f"--{k}" for k in ("eps", "force", "omega") if getattr(args, k) is None]
    if missing:
        raise InputError(f"the following arguments are required: {', '.join(missing)}")
    d = Drive(args.eps, args.force, args.omega, math.inf if args.Q is None else args.Q)
    check_steady_state(d.eps, d.Q, d.omega)
    from ..analysis.periodic import driven_report

    data = driven_report_json(driven_report(d, args.order, args.harmonics))
    print(json.dumps(data) if args.json else driven_table(data))
    return 0


def subharmonic_json(eps: float, force: float, omega: float, closed: tuple) -> dict:
    """The contract of ``lindstedt subharmonic … --json`` (eq. 10.83–10.87), a pure function
    of ``closed``, :func:`analysis.subharmonic.subharmonic`'s ``(exists, reason, solutions)``
    at ``eps``, ``force``, ``omega``."""
    exists, reason, solutions = closed
    return {
        "parameters": {"eps": eps, "force": force, "omega": omega, "drive": 3 * omega},
        "exists": exists,
        "reason": reason,
        "solutions": [{
            "root": s.root,
            "a": s.a,
            "F": s.F,
            "hill_stable": s.hill_stable,
            "floquet_moduli": sorted(float(abs(m)) for m in s.hill_multipliers),
            "numerical": None if s.orbit is None else {
                "a1": s.orbit.A[1], "a3": s.orbit.A[3], "stable": s.orbit.stable,
                "simulation_locks": s.locked,
                "floquet_moduli": sorted(float(abs(m)) for m in s.orbit.multipliers)},
            "full_hill": None if s.balance is None else {
                "a1": s.balance[0][1], "a3": s.balance[0][3], "stable": s.full_hill_stable,
                "floquet_moduli": sorted(float(abs(m)) for m in s.full_hill_multipliers)},
        } for s in solutions],
    }


def subharmonic_equation_json(text: str, name: str, found, closed: tuple | None) -> dict:
    """The contract of ``lindstedt subharmonic EQUATION --n N … --json``, a pure function of
    ``found`` (:class:`analysis.subharmonic.SubharmonicResponse`: every orbit of n drive
    periods, the primary response and the onset) and, for the notes' eq. 10.83 (n = 3,
    ``q + εq³``, undamped), ``closed``, its closed form (:func:`subharmonic_json`'s keys as
    well)."""
    problem = found.problem
    data = {"equation": text, "name": name, **subharmonic_orbits_json(found)}
    data["parameters"]["values"] = dict(problem.values)
    if closed is not None:
        notes = subharmonic_json(problem.eps, problem.force, problem.omega, closed)
        data = {**data, **notes, "parameters": {**data["parameters"], **notes["parameters"]}}
    return data


def subharmonic_equation_response(text: str, values: dict[str, str], omega: float | None,
                                  name: str = "oscillator", n: int = 3) -> tuple:
    """What ``subharmonic EQUATION`` computes, once: the orbits found
    (:func:`analysis.subharmonic.subharmonic_orbits`) and, for the notes' eq. 10.83, its
    closed form (``None`` otherwise)."""
    from ..analysis.subharmonic import subharmonic, subharmonic_equation, subharmonic_orbits

    problem = subharmonic_equation(text, values, omega, n, name)
    closed = (None if problem.eps is None else
              subharmonic(problem.eps, problem.force, problem.omega))
    return subharmonic_orbits(problem), closed


def subharmonic_orbits_json(found) -> dict:
    """The general fields of the subharmonic's JSON (:class:`subharmonic.SubharmonicResponse`)."""
    p = found.problem

    def moduli(orbit) -> list[float]:
        return sorted(float(abs(m)) for m in orbit.multipliers)

    def orbit_json(o) -> dict:
        return {"r": o.r, "A": _keyed(o.A), "B": _keyed(o.B), "stable": o.stable,
                "balance_residual": o.residual,
                "shooting": None if o.orbit is None else {
                    "a1": o.orbit.A.get(1, 0.0), "b1": o.orbit.B.get(1, 0.0),
                    "deviation": o.deviation, "floquet_moduli": moduli(o.orbit)}}

    primary = found.primary
    return {
        "n": p.n,
        "parameters": {"omega": p.omega, "drive": p.drive, "force": p.force,
                       "harmonics": found.harmonics},
        "exists": found.exists,
        "reason": found.reason,
        "orbits": [orbit_json(o) for o in found.orbits],
        "primary": None if primary is None else {
            "amplitude": math.hypot(primary.A.get(p.n, 0.0), primary.B.get(p.n, 0.0)),
            "stable": primary.stable,
            "floquet_moduli": None if primary.orbit is None else moduli(primary.orbit)},
        "onset": None if found.onset is None else {"force": found.onset.value,
                                                   "kind": found.onset.kind},
        "seeds": found.seeds,
        "note": found.note,
    }


def run_subharmonic(args: argparse.Namespace) -> int:
    """Run ``lindstedt subharmonic`` (the notes' 1/3 or an EQUATION's 1/n), as a table, JSON
    or a figure.  Returns the exit status."""
    n = 3 if args.n is None else args.n
    if _equation_args(args, ("eps", "force"), ("eps", "force", "omega")):
        values, name = _params(args.param), args.name or "oscillator"

        def draw(record: tuple, path: Path) -> Path:
            found, closed = record
            if closed is not None:  # the notes' eq. 10.83: its roots across ω
                return _subharmonic_curve_figure(found.problem.eps, found.problem.force, path)
            return _charts().subharmonic_orbits_figure(found, args.model, path)

        return _report(args, lambda: subharmonic_equation_response(args.model, values,
                                                                   args.omega, name, n),
                       lambda r: subharmonic_equation_json(args.model, name, *r), draw,
                       _subharmonic_table)
    if n != 3:
        raise InputError(f"--n {n}: the notes' eq. 10.83 (--eps, --force) is the 1/3 "
                         "subharmonic; give an EQUATION for another n")
    def closed() -> tuple:
        from ..analysis.subharmonic import subharmonic

        return subharmonic(args.eps, args.force, args.omega)

    return _report(args, closed,
                   lambda c: subharmonic_json(args.eps, args.force, args.omega, c),
                   lambda _, path: _subharmonic_curve_figure(args.eps, args.force, path),
                   _subharmonic_table)


def _subharmonic_curve_figure(eps: float, force: float, path: Path) -> Path:
    """eq. 10.87's roots across ω (:func:`analysis.curves.subharmonic_curve`), drawn."""
    from ..analysis.curves import subharmonic_curve

    return _charts().subharmonic_figure(subharmonic_curve(eps, force), path)


def _subharmonic_table(data: dict) -> list[str]:
    p = data["parameters"]
    if "solutions" not in data:
        return _orbits_table(data)
    lines = [f"omega^2 q'' + q + eps q^3 = f cos 3tau: eps = {p['eps']}, f = {p['force']}, "
             f"omega = {p['omega']} (drive at {p['drive']:g})",
             ("exists: " if data["exists"] else "no subharmonic: ") + data["reason"]]
    for s in data["solutions"]:
        num = s["numerical"]
        true = "no orbit found" if num is None else (
            f"true orbit a1 = {num['a1']:.6f}, {'stable' if num['stable'] else 'unstable'}, "
            f"a simulation 1% off it {'locks on' if num['simulation_locks'] else 'drifts away'}")
        full = s["full_hill"]
        lines.append(f"  root {s['root']}: a = {s['a']:.6f}, Hill: "
                     f"{'stable' if s['hill_stable'] else 'unstable'}; full Hill: "
                     + ("no balance" if full is None else
                        f"{'stable' if full['stable'] else 'unstable'} (a1 = {full['a1']:.6f})")
                     + f"; {true}")
    if "orbits" in data:
        lines += _orbits_table(data)[2:]
    return lines


def _orbits_table(data: dict) -> list[str]:
    p, n = data["parameters"], data["n"]
    lines = [f"{data['equation']}: orbits of {n} drive periods (the 1/{n} subharmonic), "
             f"omega = {p['omega']:g}, drive at {p['drive']:g}, f = {p['force']:g}",
             ("exists: " if data["exists"] else "no subharmonic: ") + data["reason"]]
    for i, o in enumerate(data["orbits"], 1):
        shot = o["shooting"]
        verdict = ("shooting found no orbit" if shot is None else
                   f"{'stable' if o['stable'] else 'unstable'} (Floquet |lambda| max "
                   f"{max(shot['floquet_moduli']):.6g}), shooting agrees to "
                   f"{shot['deviation']:.1e}")
        lines.append(f"  orbit {i}: r = {o['r']:.8f} (A1 = {o['A']['1']:.8f}, "
                     f"B1 = {o['B']['1']:.8f}); {verdict}")
    pr = data["primary"]
    if pr is None:
        lines.append("  primary response (one drive period): not found (Newton from the linear "
                     "response and from rest did not converge)")
    else:
        lines.append(f"  primary response (one drive period): harmonic {n} amplitude "
                     f"{pr['amplitude']:.8f}, "
                     + ("not shot" if pr["stable"] is None else
                        "stable" if pr["stable"] else "unstable"))
    if data.get("note"):
        lines.append(f"  note: {data['note']}")
    on = data["onset"]
    if on is not None:
        how = "a fold" if on["kind"] == "fold" else "a bifurcation off the primary response"
        lines.append("  onset at this omega: " + (
            "none: the orbits continue down to f = 0" if on["kind"] == "none" else
            f"f = {on['force']:.8g} ({how})"))
    return lines


def parametric_report_json(report) -> dict:
    """The JSON of a :class:`analysis.parametric.ParametricReport`, a pure function of it: the
    tongue, the onsets, the fold and every branch point (one harmonic, balance with its
    full-Hill verdict, shooting)."""
    def moduli(lam) -> list[float]:
        return sorted(float(abs(m)) for m in lam)

    from ..analysis.parametric import outside_model

    p, (lo, hi), edges, top = report.pump, report.omega_range, report.tongue, report.fold

    def where(omega: float, r: float | None = None) -> dict:
        """Whether ``omega`` lies in the range and ``(omega, r)`` in the model, in words."""
        notes = [] if lo <= omega <= hi else [f"outside the range [{lo:g}, {hi:g}]"]
        model = "" if r is None else outside_model(p, r)
        return {"in_range": lo <= omega <= hi, **({} if r is None else {"in_model": not model}),
                "note": "; ".join([*notes, *([model] if model else [])])}

    return {
        "equation": "q'' + 2 zeta q' + (1 + eps cos 2wt) q + gamma q^3 = 0",
        "parameters": {"eps": p.eps, "zeta": p.zeta, "gamma": p.gamma, "omega_from": lo,
                       "omega_to": hi, "points": report.points, "harmonics": report.harmonics},
        "tongue": None if edges is None else {
            "lower": edges[0], "upper": edges[1],
            "lower_in_range": lo <= edges[0] <= hi, "upper_in_range": lo <= edges[1] <= hi},
        "onsets": [{"omega": o.value, "branch": o.branch, "supercritical": o.supercritical,
                    **where(o.value, 0.0)} for o in report.onsets],
        "fold": None if top is None else {"omega": top[0], "r": top[1], **where(*top)},
        "branches": [{
            "branch": r.one.branch, "omega": r.one.omega,
            "one_harmonic": {"a": r.one.a, "b": r.one.b, "r": r.one.r, "stable": r.one.stable},
            "balance": None if r.balance is None else {
                "r": r.balance.r, "residual": r.balance.residual,
                "full_hill_stable": r.balance.stable,
                "floquet_moduli": moduli(r.balance.multipliers)},
            "shooting": None if r.orbit is None else {
                "r": math.hypot(r.orbit.A[1], r.orbit.B[1]), "stable": r.orbit.stable,
                "floquet_moduli": moduli(r.orbit.multipliers)},
        } for r in report.rows],
    }


def _parametric_table(data: dict) -> list[str]:
    p, t = data["parameters"], data["tongue"]
    lines = [f"{data['equation']}: eps = {p['eps']}, zeta = {p['zeta']}, gamma = {p['gamma']}",
             "tongue (one harmonic): " + ("closed by the damping" if t is None else
                                          f"{t['lower']:.6f} < omega < {t['upper']:.6f}")
             + ("" if t is None or (t.get("lower_in_range", True)
                                    and t.get("upper_in_range", True)) else
                f" (an edge outside the range [{p['omega_from']:g}, {p['omega_to']:g}])")]
    for o in data["onsets"]:
        lines.append(f"onset of branch {o['branch']} at omega = {o['omega']:.6f}: "
                     + ("supercritical" if o["supercritical"] else "subcritical")
                     + (f" ({o['note']})" if o.get("note") else ""))
    f = data["fold"]
    if f is not None:
        lines.append(f"fold (branches + and - meet): omega = {f['omega']:.6g}, "
                     f"r = {f['r']:.6g}" + (f" ({f['note']})" if f.get("note") else ""))
    lines.append(f"{'omega':>9} {'branch':>6} {'r (1 harm.)':>12} {'stable':>7} "
                 f"{'r (balance)':>12} {'full Hill':>9} {'r (shot)':>12} {'shot':>8}")
    lines.append("  (branch 0 is q = 0: its Floquet multipliers are Mathieu's; a balance 'none' "
                 "fell onto q = 0: the true tongue is O(eps^2) off the one-harmonic one)")
    for b in data["branches"]:
        one, bal, shot = b["one_harmonic"], b["balance"], b["shooting"]
        lines.append((
            f"{b['omega']:>9.5f} {b['branch']:>6} {one['r']:>12.8f} "
            f"{'yes' if one['stable'] else 'no':>7} "
            + (f"{'' if b['branch'] == '0' else 'none':>12} {'':>9}" if bal is None else
               f"{bal['r']:>12.8f} {'yes' if bal['full_hill_stable'] else 'no':>9}")
            + ("" if shot is None else
               f" {shot['r']:>12.8f} {'stable' if shot['stable'] else 'unstable':>8}"))
            .rstrip())
    return lines


def run_parametric(args: argparse.Namespace) -> int:
    """Run ``lindstedt parametric``: the pumped Duffing oscillator over an ω range, as a
    table, JSON or a figure.  Returns the exit status."""
    if args.omega_min is None or args.omega_max is None:
        raise InputError("the following arguments are required: --omega A:B[:N]")

    def report():
        from ..analysis.parametric import parametric_report

        return parametric_report(args.eps, args.zeta, args.gamma, args.omega_min,
                                 args.omega_max, args.points, args.harmonics)

    return _report(args, report, parametric_report_json,
                   lambda r, path: _charts().parametric_figure(r, path),
                   _parametric_table)


def mixing_json(m) -> dict:
    """The contract of ``lindstedt mixing … --json``, a pure function of a
    :class:`analysis.mixing.Mixing`: predicted and simulated tones of ``q̈ + g = Σ f_i cos
    ω_i t``; ``eps`` and ``Q`` among the parameters when ``g`` is the notes' ``q + εq³ +
    q̇/Q``."""
    from ..analysis.mixing import tone_label

    series, fit, terms = m.series, m.fit, m.table.terms
    parameters: dict = {}
    if set(terms) <= {(1, 0), (3, 0), (0, 1)} and terms.get((1, 0)) == 1.0:
        parameters = {"eps": terms.get((3, 0), 0.0), "Q": 1 / terms[(0, 1)]}
    return {
        "parameters": {**parameters, "drives": [{"force": f, "omega": w} for f, w in m.drives]},
        "expansion_parameter": series.expansion_parameter,
        "converged": series.converged,
        "reason": series.reason,
        "simulated_rms_residual": fit.rms_residual,
        "mean": {"predicted": series.mean, "simulated": fit.mean},
        "tones": [{"frequency": t.frequency, "combination": tone_label(t.combination),
                   "order": t.order, "predicted": t.predicted, "simulated": float(a),
                   "simulated_uncertainty": float(u), "resolved": bool(a > 3 * u)}
                  for t, a, u in zip(series.tones, fit.amplitudes, fit.uncertainty,
                                     strict=True)],
    }


def mixing_equation_json(m, text: str, name: str = "oscillator") -> dict:
    """:func:`mixing_json` of a user's equation, with ``equation``, ``name`` and the
    ``parameters.values`` given."""
    data = mixing_json(m)
    data["parameters"]["values"] = dict(m.values)
    return {"equation": text, "name": name, **data}


def _drive(text: str) -> tuple[float, float]:
    try:
        f, w = text.split("@")
        return float(f), float(w)
    except ValueError:
        raise argparse.ArgumentTypeError(f"drive {text!r}: expected F@W, e.g. 0.3@1.3") from None


def run_mixing(args: argparse.Namespace) -> int:
    """Run ``lindstedt mixing`` (the notes' Duffing or an EQUATION): the combination tones
    of a multi-tone drive, as a table, JSON or a figure, computed once.  Returns the exit
    status."""
    from ..analysis.mixing import duffing_mixing, equation_mixing

    if _equation_args(args, ("eps", "Q", "drive"), ("eps", "Q", "drive")):
        values, name = _params(args.param), args.name or "oscillator"
        return _report(args, lambda: equation_mixing(args.model, values, name),
                       lambda m: mixing_equation_json(m, args.model, name),
                       lambda m, path: _charts().mixing_figure(m, path, args.model),
                       _mixing_table)
    return _report(args, lambda: duffing_mixing(args.eps, args.Q, args.drive), mixing_json,
                   lambda m, path: _charts().mixing_figure(m, path,
                                                           f"ε = {args.eps}, Q = {args.Q}"),
                   _mixing_table)


def _mixing_table(data: dict) -> list[str]:
    p = data["parameters"]
    head = (f"{data['equation']}: " if "equation" in data else
            f"q'' + q'/Q + q + eps q^3 = sum f_i cos(w_i t): eps = {p['eps']}, Q = {p['Q']}, ")
    lines = [head + ", ".join(f"w{i} = {d['omega']} (f = {d['force']})"
                         for i, d in enumerate(p["drives"], 1)),
             ("" if data["converged"] else "warning: ") + data["reason"]]
    mean = data["mean"]
    if mean["predicted"] != 0:  # an even term's offset (an odd force has none)
        lines.append(f"mean (offset): predicted {mean['predicted']:.3e}, simulated "
                     f"{mean['simulated']:.3e}")
    lines.append(f"{'tone':>12} {'frequency':>10} {'order':>6} {'predicted':>11} "
                 f"{'simulated':>11} {'+/-':>9}")
    for t in data["tones"]:
        lines.append(f"{t['combination']:>12} {t['frequency']:>10.4f} {t['order']:>6} "
                     f"{t['predicted']:>11.3e} {t['simulated']:>11.3e} "
                     f"{t['simulated_uncertainty']:>9.1e}"
                     + ("" if t["resolved"] else "  (below the fit's noise)"))
    return lines


def arguments_driven(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt driven``'s arguments."""
    p = sub.add_parser("driven", help="steady 1:1 response of a driven oscillator",
                       description="q'' + q'/Q + q + eps q^3 = f cos(w t) (--eps, --force, --Q): "
                       "every 1:1 branch by the μ-expansion, harmonic balance and shooting; or "
                       "your own equation q'' + g(q, q') = f*cos(w*t), g a polynomial, with "
                       "--param for its parameters: every 1:1 orbit by harmonic balance and "
                       "shooting.")
    _flag_equation(p, "\"q'' + q + eps*q**3 + gamma*q'**3 = f*cos(w*t)\" (a polynomial "
                   "force, one drive f*cos(w*t) whose w is --omega)",
                   "Duffing's q'' + q'/Q + q + εq³ = f cos ωt with --eps, --force, --Q",
                   "every parameter but w needs one")
    _flag_drive(p, required=False, omega="ω, the drive frequency (required)", Q="none",
                notes=True)
    p.add_argument("--Q", type=_quality, default=None, metavar="Q",
                   help="quality factor Q > 0 of the damping q'/Q (default: inf, undamped)")
    _flag_order(p, "μ-expansion order K")
    _flag_harmonics(p, "odd harmonics N of harmonic balance")
    _flag_json(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p


def arguments_subharmonic(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt subharmonic``'s arguments."""
    p = sub.add_parser("subharmonic", help="orbits of n drive periods (the 1/n subharmonic) "
                       "and their stability",
                       description="Your own driven oscillator q'' + g(q, q') = f cos(n w t), g "
                       "any polynomial (damped or not): every orbit of n drive periods by "
                       "harmonic balance on the harmonics of w, each shot for its Floquet "
                       "stability, the primary response and the onset (the smallest drive "
                       "amplitude with such an orbit at this w). Without EQUATION: Duffing's "
                       "omega^2 q'' + q + eps q^3 = f cos 3τ in closed form (--eps, --force, "
                       "--omega).")
    _flag_equation(p, "\"x'' + 0.05*x' + x + x**2 = f*cos(w*t)\" (the drive at n times the "
                   "subharmonic's frequency ω: w = n*omega in f*cos(w*t), w = omega in "
                   "f*cos(n*w*t), or a number n*omega without --omega)")
    p.add_argument("--n", type=_positive, default=None, metavar="N",
                   help="the subharmonic's order: orbits of N drive periods, 2..12 (default 3; "
                   "1/2 needs an even power in the force, 1/3 an odd one)")
    _flag_drive(p, required=False, omega="ω, the subharmonic's own frequency: the drive is at "
                "n·ω (required, unless the equation's drive frequency is a number)", Q=None,
                notes=True)
    _flag_json(p)
    _flag_plot(p)
    return p


def arguments_parametric(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt parametric``'s arguments."""
    p = sub.add_parser("parametric", help="the parametrically driven oscillator's response "
                       "in its first tongue",
                       description="q'' + 2 zeta q' + (1 + eps cos 2wt) q + gamma q^3 = 0: the "
                       "1:1 response at w (the pump at 2w), every branch with its stability "
                       "(one harmonic, harmonic balance with the full Hill equation, shooting), "
                       "the tongue's edges, the onsets and the fold.")
    p.add_argument("--eps", type=_real, required=True, metavar="EPS",
                   help="ε, the pump depth, 0 < ε < 1 (required)")
    p.add_argument("--zeta", type=_real, default=0.0, metavar="ZETA",
                   help="ζ ≥ 0, the damping ratio of 2ζq' (default 0: undamped)")
    p.add_argument("--gamma", type=_real, default=1.0, metavar="GAMMA",
                   help="γ, the cubic stiffness (> 0 hardens, < 0 softens; default 1)")
    _flag_omega(p, ("A:B", "A:B:N"), "the frequencies ω (half the pump frequency) from A to "
                "B, in units of the linear natural frequency, N points in "
                f"2..{PARAMETRIC_MAX_POINTS} (default 41) (required)", points=41)
    _flag_range_bounds(p, "--omega-from", "--omega-to")
    _deprecated(p, "--points", "--omega A:B:N", "points", type=_positive)
    _flag_harmonics(p, "odd harmonics of the balance (1, 3, …, 2N − 1)")
    _flag_json(p)
    _flag_plot(p)
    return p


def arguments_mixing(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt mixing``'s arguments."""
    p = sub.add_parser("mixing", help="combination tones of a drive of up to four tones",
                       description="Your own q'' + g(q, q') = Σ f_i cos(w_i t), g any "
                       "polynomial with a linear stiffness and damping: the combination tones "
                       "predicted to the second order of the nonlinearity, beside a simulated "
                       "steady state; or Duffing's q'' + q'/Q + q + eps q^3 (--eps, --Q, "
                       "--drive).")
    _flag_equation(p, "\"x'' + x'/20 + x + x**2/5 + x**3/10 = 3/20*cos(13*t/10) + "
                   "3/20*cos(17*t/10)\" (every frequency a number or a name given with "
                   "--param: the tones are numbered by ascending frequency)")
    _flag_drive(p, required=False, omega=None, Q=None, force=False, notes=True)
    p.add_argument("--Q", type=_quality, default=None, metavar="Q",
                   help="quality factor Q > 0 of the damping q'/Q (finite; required without "
                   "EQUATION)")
    p.add_argument("--drive", type=_drive, action="append", metavar="F@W",
                   help="a drive f cos(w t): amplitude F at frequency W (units of the linear "
                   "natural frequency), e.g. 0.3@1.3; repeat for each tone (required without "
                   "EQUATION)")
    _flag_json(p)
    _flag_plot(p)
    return p
