"""``ssm``: the spectral submanifold of one mode of a damped (and driven) system, a SYSTEM
written as text or a model folder: its arguments, its JSON contract, its table and CSV, each
a pure function of the one record (:class:`analysis.ssm.Reduction`)."""

from __future__ import annotations

import argparse
import json
import math

from ..errors import InputError
from ..limits import SSM_MAX_ORDER, SSM_MAX_POINTS, check_int

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    _flag_allow_slow,
    _flag_csv,
    _flag_json,
    _flag_omega,
    _flag_plot,
    _params,
    _positive,
    _positive_real,
    check_outputs,
    write_csv,
)

DEFAULT_ORDER = 7
FRC_POINTS = 500
# NOTE: the forced response's default grid (the reduced model answers 500 drive frequencies
# in a fraction of a second).


def _order(text: str) -> int:
    k = _positive(text)
    if k > SSM_MAX_ORDER:
        raise argparse.ArgumentTypeError(f"{k}: the SSM is computed to order ≤ {SSM_MAX_ORDER} "
                                         "(floating-point terms past it are rounding)")
    return k


def _modes(text: str) -> tuple[int, ...]:
    """``--mode``: one mode ``M``, or a pair ``M1,M2`` in internal resonance."""
    return tuple(_positive(part.strip()) for part in text.split(","))


def _pair(z: complex) -> list[float]:
    return [float(z.real), float(z.imag)]


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def ssm_json(red) -> dict:
    """The contract of ``lindstedt ssm … --json``, a pure function of a
    :class:`analysis.ssm.Reduction`: ``kind``, ``mode``, ``lambda`` and ``gamma`` as
    ``[re, im]`` pairs (``gamma[j]`` the coefficient of ``ρ^{2j}`` in ``a + iω``), the
    ``backbone`` (``rho``, ``omega``, ``damping_ratio``, each output's ``amplitude``
    ``max |x|`` over a period, and ``error_estimate``) and, with a drive, ``frc`` (each
    steady state: ``omega``, ``amplitude``, ``stable``, and ``rho``, ``phase``), its folds;
    beside them the order, outputs, each order's ``residual`` (the backward error of its
    homological equations' solves), the near resonances, the radius."""
    m = red.model
    names = list(red.names)
    backbone = [{"rho": float(r), "omega": float(m.omega(r)),
                 "damping_ratio": float(m.damping_ratio(r)),
                 "amplitude": {name: float(a) for name, a in zip(names, amp, strict=True)},
                 "error_estimate": float(m.error(r))}
                for r, amp in zip(red.rho, red.amplitude, strict=True)]
    lam = m.lam
    data = {"kind": "ssm", "mode": m.mode, "lambda": _pair(lam),
            "gamma": [_pair(g) for g in m.gamma], "backbone": backbone,
            "order": m.order, "system": red.text, "coordinates": m.matrices.size,
            "outputs": {name: int(i) for name, i in zip(names, red.outputs, strict=True)},
            "linear": {"omega0": abs(lam), "damped_frequency": lam.imag,
                       "damping_ratio": -lam.real / abs(lam) + 0.0},
            "reduced_dynamics": "rho' = rho*a(rho), theta' = omega(rho), a + i*omega = "
                                "sum_j gamma[j]*rho^(2j); x = W(rho*e^(i*theta), "
                                "rho*e^(-i*theta)), W's linear part rho*2*Re(phi*e^(i*theta)) "
                                "with phi^H M phi = 1/4",
            "residual": [float(r) for r in m.residual],
            "near_resonances": [{"order": q.order, "monomial": list(q.monomial),
                                 "eigenvalue": _pair(q.eigenvalue), "divisor": q.divisor,
                                 "relative": q.relative} for q in m.near],
            "modes_checked": m.linear.checked,
            "radius_estimate": {"value": _finite(m.radius), "how": m.radius_how}}
    if red.response is not None:
        r = red.response
        data["frc"] = [{"omega": s.omega, "amplitude": {
            name: float(a) for name, a in zip(names, s.amplitude, strict=True)},
            "stable": s.stable, "rho": s.rho, "phase": s.psi} for s in r.states]
        data["frc_folds"] = [{"omega": w, "rho": rho} for w, rho in r.folds]
        data["frc_beyond_radius"] = r.beyond
        data["frc_peaks"] = {name: None if p is None else {
            "omega": float(p.omega), "rho": float(p.rho), "amplitude": p.amplitude}
            for name, p in zip(names, r.peaks, strict=True)}
        data["frc_method"] = ("the non-autonomous SSM at first order in the drive and to "
                              f"order {max(m.order - 1, 0)} in p; peaks refined along the "
                              "curve in rho")
    return data


def _number(x: float | None) -> str:
    return "-" if x is None else f"{x:.6g}"


def ssm_table(data: dict) -> list[str]:
    """The readable table of :func:`ssm_json`'s ``data``."""
    names = list(data["outputs"])
    lam, lin = data["lambda"], data["linear"]
    lines = [f"SSM of mode {data['mode']} of {data['system']} ({data['coordinates']} "
             f"coordinate{'s' * (data['coordinates'] != 1)}), order {data['order']}, "
             "floating point",
             f"lambda = {lam[0]:.9g} {'+-'[lam[1] < 0]} {abs(lam[1]):.9g}i: omega0 = "
             f"{lin['omega0']:.9g}, damping ratio {lin['damping_ratio']:.6g}",
             data["reduced_dynamics"],
             f"{'j':>3}  {'Re gamma_j':>16}  {'Im gamma_j':>16}"]
    lines += [f"{j:>3}  {g[0]:>16.9g}  {g[1]:>16.9g}" for j, g in enumerate(data["gamma"])]
    if "gamma_exact" in data:
        ex = data["gamma_exact"]
        lines.append(f"exact ground: lambda a root of {ex['field']['lambda_polynomial']} "
                     f"(the field of degree {ex['field']['degree']}); {ex['normalisation']}, "
                     f"gamma[j] = gamma_exact[j]*({ex['factor']['exact']})**j; floating point "
                     f"agrees to {ex['agreement']:.1e} (--json holds every exact form)")
    lines.append("backward error of the homological equations' sparse solves, worst order: "
                 f"{max(data['residual']):.2g}")
    near = data["near_resonances"]
    lines.append("near resonances (divisor |s - lambda_j| under 10 % of |lambda_j|), among "
                 f"{data['modes_checked']}: " + ("none" if not near else "; ".join(
                     f"order {q['order']} p1^{q['monomial'][0]} p2^{q['monomial'][1]} with "
                     f"lambda = {q['eigenvalue'][0]:.6g} + {q['eigenvalue'][1]:.6g}i, divisor "
                     f"{q['divisor']:.3g}" for q in near)))
    radius = data["radius_estimate"]
    lines.append(f"radius in rho estimated at {_number(radius['value'])} ({radius['how']})")
    lines.append("backbone (amplitude: max |x| over a period):")
    lines.append(f"{'rho':>10}  {'omega':>12}  {'damping':>10}  " + "  ".join(
        f"{n:>10}" for n in names) + f"  {'error':>8}")
    points = data["backbone"]
    for p in points[::max(1, (len(points) - 1) // 10)]:
        lines.append(f"{p['rho']:>10.5g}  {p['omega']:>12.9g}  {p['damping_ratio']:>10.5g}  "
                     + "  ".join(f"{p['amplitude'][n]:>10.5g}" for n in names)
                     + f"  {p['error_estimate']:>8.1e}")
    if "frc" in data:
        frc = data["frc"]
        lines.append(f"forced response: {len(frc)} steady states over "
                     f"{len({s['omega'] for s in frc})} drive frequencies"
                     + (f" ({data['frc_beyond_radius']} beyond the radius dropped)"
                        if data["frc_beyond_radius"] else ""))
        for n in names:
            p = data["frc_peaks"][n]
            lines.append(f"  peak of {n}: not inside the radius and the range (widen --omega, "
                         "or raise --order)" if p is None else
                         f"  peak of {n}: {p['amplitude']:.9g} at omega = {p['omega']:.9g} "
                         f"(rho = {p['rho']:.6g})")
        lines += [f"  fold at omega = {f['omega']:.9g}, rho = {f['rho']:.6g}"
                  for f in data["frc_folds"]]
    return lines


def ssm_csv(data: dict, path) -> None:
    """``--csv``: the backbone's rows, then the forced response's (``frc`` says which; a
    column that does not apply holds NaN)."""
    names = list(data["outputs"])
    nan = math.nan
    columns = (("frc", "1 a steady state of the forced response and 0 a backbone point"),
               ("omega", "frequency"), ("rho", "normal-form amplitude"),
               ("damping_ratio", "backbone only"),
               *((n, f"max |{n}| over a period") for n in names),
               ("stable", "forced response only: 1 stable and 0 not"))
    rows = [(0, p["omega"], p["rho"], p["damping_ratio"], *(p["amplitude"][n] for n in names),
             nan) for p in data["backbone"]]
    rows += [(1, s["omega"], s["rho"], nan, *(s["amplitude"][n] for n in names),
              int(s["stable"])) for s in data.get("frc", [])]
    write_csv(path, columns, rows)


def _outputs(text: str | None, names: list[str]) -> list[int] | None:
    """``--output``: indices (0-based) or coordinate names, comma-separated (``None``: the
    default, :func:`analysis.ssm.reduce`'s)."""
    if text is None:
        return None
    out = []
    for part in text.split(","):
        part = part.strip()
        if part in names:
            out.append(names.index(part))
            continue
        try:
            k = int(part)
        except ValueError:
            raise InputError(f"--output {text}: {part!r} is neither a coordinate name nor an "
                             "index") from None
        if not 0 <= k < len(names):
            raise InputError(f"--output {text}: index {k} outside 0..{len(names) - 1}")
        out.append(k)
    if len(set(out)) != len(out):
        raise InputError(f"--output {text}: a coordinate named twice")
    return out


def run_ssm(args: argparse.Namespace) -> int:
    """Run ``lindstedt ssm``: read the system (text or folder), reduce, print."""
    from ..analysis.ssm_forced import reduce

    if len(args.mode) > 1:
        return run_resonant(args)
    (mode,) = args.mode
    plot, csv = check_outputs(args)
    system = _system(args.system, args.model, args.param)
    check_int(args.points, 2, SSM_MAX_POINTS, f"--omega …:{args.points}: the forced response "
              f"takes 2..{SSM_MAX_POINTS} drive frequencies")
    span = None
    if args.omega_min is not None:
        span = (args.omega_min, args.omega_max)
        if not 0 < span[0] < span[1]:
            raise InputError(f"--omega {span[0]:g}:{span[1]:g}: give 0 < A < B")
    exact = None
    if args.exact:  # first: a refusal costs nothing
        from ..derive.ssm_exact import exact_gamma

        exact = exact_gamma(system, mode, args.order)
    red = reduce(system, mode, args.order,
                 _outputs(args.output, [str(x) for x in system.coordinates]), args.rho_max,
                 span, args.points)
    data = ssm_json(red)
    if exact is not None:
        data["gamma_exact"] = exact.json()
        worst = max(abs(complex(*g) - z) / max(abs(z), 1e-300)
                    for g, z in zip(data["gamma"], exact.gamma, strict=True))
        data["gamma_exact"]["agreement"] = worst
    if plot is not None:
        from ..charts_modes import ssm_figure

        ssm_figure(data, plot)
    if csv is not None:
        ssm_csv(data, csv)
    print(json.dumps(data) if args.json else "\n".join(ssm_table(data)))
    return 0


def resonant_json(red) -> dict:
    """``lindstedt ssm SYSTEM --mode M1,M2 --json``, a pure function of an
    :class:`analysis.ssm_resonant.ResonantReduction`: ``kind``, ``modes``, ``lambda`` (two
    ``[re, im]`` pairs), the ratio and detuning, the reduced dynamics' kept ``terms`` (each
    with its monomial in ``(p1, conj p1, p2, conj p2)``, its coefficient and its polar form),
    the single-mode ``families`` where their planes are invariant, an undamped pair's
    ``coupled_modes`` (at ψ = 0 and π: ``rho``, ``omega``, amplitudes), each order's
    ``residual``, the near resonances of the monomials not kept, the radius; driven, the
    forced response ``frc`` (each steady state's ``omega``, ``amplitude``, ``stable``,
    ``rho``, ``u``), its folds and peaks."""
    m = red.model
    names = list(red.names)
    r = m.ratio
    terms = [{"equation": f"p{t.mode}", "monomial": list(t.monomial),
              "coefficient": _pair(t.coefficient),
              "polar": {"rho1": t.rho1, "rho2": t.rho2, "psi": t.psi}} for t in red.terms]
    families = [{"mode": f.mode, "gamma": [_pair(g) for g in f.gamma], "backbone": [
        {"rho": float(rho), "omega": float(w), "damping_ratio": float(z),
         "amplitude": {name: float(a) for name, a in zip(names, amp, strict=True)}}
        for rho, w, z, amp in zip(f.rho, f.omega, f.damping_ratio, f.amplitude, strict=True)]}
        for f in red.families]
    return {"kind": "ssm", "modes": list(m.modes), "lambda": [_pair(lam) for lam in m.lam],
            "ratio": f"1:{r}", "detuning": m.detuning, "order": m.order, "system": red.text,
            "coordinates": m.matrices.size,
            "outputs": {name: int(i) for name, i in zip(names, red.outputs, strict=True)},
            "shapes": [[_pair(z) for z in lin.shape[red.outputs]] for lin in m.linear],
            "reduced_dynamics": "d(p_k)/dt = lambda_k*p_k + the sum of the terms of equation "
                                "p_k, each coefficient*p1^a*conj(p1)^b*p2^c*conj(p2)^d "
                                "(monomial [a, b, c, d]); x = W(p), W's linear part "
                                "2*Re(phi1*p1 + phi2*p2) with phi_k^H M phi_k = 1/4",
            "polar": f"p_k = rho_k*e^(i*theta_k), psi = theta2 - {r}*theta1: d(rho_k)/dt + "
                     "i*rho_k*d(theta_k)/dt = lambda_k*rho_k + the sum of the terms of "
                     "equation p_k, each coefficient*rho1^m*rho2^n*e^(i*s*psi), (m, n, s) "
                     "its polar powers (rho1, rho2, psi)",
            "terms": terms, "families": families,
            "coupled_modes": [{"psi": c.psi, "points": [
                {"rho": [float(a), float(b)], "omega": float(w),
                 "amplitude": {name: float(x) for name, x in zip(names, amp, strict=True)}}
                for (a, b), w, amp in zip(c.rho, c.omega, c.amplitude, strict=True)]}
                for c in red.coupled],
            "residual": [float(x) for x in m.residual],
            "near_resonances": [{"order": q.order, "monomial": list(q.monomial),
                                 "eigenvalue": _pair(q.eigenvalue), "divisor": q.divisor,
                                 "relative": q.relative} for q in m.near],
            "modes_checked": m.linear[0].checked,
            "radius_estimate": {"value": _finite(m.radius), "how": m.radius_how},
            **({} if red.slow_flow is None else {"slowflow_variables": {
                "scale": list(red.slow_flow),
                "map": "slowflow SYSTEM's x = sum_k a_k*s_k*cos(omega_k*t + phi_k): a_k = "
                       "|scale_k|*rho_k, phi_k = theta_k - omega_k*t (- pi where scale_k < 0); "
                       "at first order the two flows are equal"}}),
            **_pair_frc(red, names)}


def _pair_frc(red, names: list[str]) -> dict:
    """The forced response's keys of :func:`resonant_json` (none where not driven)."""
    r = red.response
    if r is None:
        return {}
    peaks = {}
    for k, name in enumerate(names):
        best = max(r.states, key=lambda s: s.amplitude[k], default=None)
        peaks[name] = None if best is None else {"omega": best.omega,
                                                 "amplitude": float(best.amplitude[k])}
    return {"frc": [{"omega": s.omega, "amplitude": {
        name: float(a) for name, a in zip(names, s.amplitude, strict=True)},
        "stable": s.stable, "rate": s.rate, "rho": list(s.rho), "u": [_pair(u) for u in s.u]}
        for s in r.states],
        "frc_folds": list(r.folds), "frc_pieces": list(r.pieces),
        "frc_beyond_radius": r.beyond,
        "frc_driven_mode": red.model.modes[0 if r.kappa == 1 else 1],
        "frc_forcing": [_pair(a) for a in r.forcing], "frc_peaks": peaks,
        "frc_method": "the drive at leading order (order 0 in p) on the directions resonant "
                      "with it; p_k = u_k*e^(i*nu_k*w*t/kappa), the reduced system's steady "
                      "states continued in w from the linear response at both ends "
                      "and from the branch points along them (pseudo-arclength), stable where "
                      "its Jacobian's eigenvalues have negative real parts (rate: the largest); "
                      "a subharmonic state once (|arg u1| <= pi/kappa); isolas not sought"}


def resonant_table(data: dict) -> list[str]:
    """The readable table of :func:`resonant_json`'s ``data``."""
    m1, m2 = data["modes"]
    lines = [f"SSM of modes {m1},{m2} of {data['system']} ({data['coordinates']} "
             f"coordinate{'s' * (data['coordinates'] != 1)}), order {data['order']}, "
             f"floating point: near {data['ratio']} resonance (omega{m2}/omega{m1} - "
             f"{data['ratio'][2:]} = {data['detuning']:.6g})"]
    lines += [f"lambda{k + 1} = {lam[0]:.9g} {'+-'[lam[1] < 0]} {abs(lam[1]):.9g}i"
              for k, lam in enumerate(data["lambda"])]
    lines += [data["reduced_dynamics"], data["polar"]]
    lines.append(f"{'equation':>8}  {'monomial':>12}  {'Re':>16}  {'Im':>16}  "
                 f"{'rho1^':>5}  {'rho2^':>5}  {'psi':>4}")
    for t in data["terms"]:
        lines.append(f"{t['equation']:>8}  {' '.join(str(e) for e in t['monomial']):>12}  "
                     f"{t['coefficient'][0]:>16.9g}  {t['coefficient'][1]:>16.9g}  "
                     f"{t['polar']['rho1']:>5}  {t['polar']['rho2']:>5}  "
                     f"{t['polar']['psi']:>4}")
    lines.append("backward error of the homological equations' sparse solves, worst order: "
                 f"{max(data['residual']):.2g}")
    near = data["near_resonances"]
    lines.append("near resonances of the monomials not kept (divisor under 10 % of "
                 f"|lambda_j|), among {data['modes_checked']}: " + ("none" if not near else
                 "; ".join(f"order {q['order']} monomial {q['monomial']} with lambda = "
                           f"{q['eigenvalue'][0]:.6g} + {q['eigenvalue'][1]:.6g}i, divisor "
                           f"{q['divisor']:.3g}" for q in near)))
    radius = data["radius_estimate"]
    lines.append(f"radius in max |p_k| estimated at {_number(radius['value'])} "
                 f"({radius['how']})")
    if "slowflow_variables" in data:
        c1, c2 = data["slowflow_variables"]["scale"]
        lines.append(f"slowflow SYSTEM's variables: a1 = {abs(c1):.9g}*rho1, a2 = "
                     f"{abs(c2):.9g}*rho2, " + ", ".join(
                         f"phi{k} = theta{k} - omega{k}*t" + (" - pi" if c < 0 else "")
                         for k, c in ((1, c1), (2, c2))))
    names = list(data["outputs"])
    for f in data["families"]:
        lines.append(f"mode {f['mode']} alone (its plane is invariant), backbone "
                     "(amplitude: max |x| over a period):")
        lines.append(f"{'rho':>10}  {'omega':>12}  {'damping':>10}  " + "  ".join(
            f"{n:>10}" for n in names))
        points = f["backbone"]
        for p in points[::max(1, (len(points) - 1) // 10)]:
            lines.append(f"{p['rho']:>10.5g}  {p['omega']:>12.9g}  {p['damping_ratio']:>10.5g}"
                         "  " + "  ".join(f"{p['amplitude'][n]:>10.5g}" for n in names))
    if not data["families"]:
        lines.append("no mode alone: the resonance couples both planes")
    for c in data["coupled_modes"]:
        lines.append(f"coupled modes at psi = {c['psi']:.6g} (phase-locked periodic motions, "
                     f"period 2*pi/omega; mode {m2} turns {data['ratio'][2:]} times as fast):")
        lines.append(f"{'rho1':>10}  {'rho2':>10}  {'omega':>12}  " + "  ".join(
            f"{n:>10}" for n in names))
        points = c["points"]
        for p in points[::max(1, (len(points) - 1) // 10)]:
            lines.append(f"{p['rho'][0]:>10.5g}  {p['rho'][1]:>10.5g}  {p['omega']:>12.9g}  "
                         + "  ".join(f"{p['amplitude'][n]:>10.5g}" for n in names))
    if "frc" in data:
        frc = data["frc"]
        lines.append(f"forced response near mode {data['frc_driven_mode']}: {len(frc)} steady "
                     f"states ({sum(not s['stable'] for s in frc)} unstable) along "
                     f"{len(data['frc_pieces'])} traced curve"
                     f"{'s' * (len(data['frc_pieces']) != 1)}"
                     + (f" ({data['frc_beyond_radius']} beyond the radius dropped)"
                        if data["frc_beyond_radius"] else ""))
        for n in names:
            p = data["frc_peaks"][n]
            if p is not None:
                lines.append(f"  peak of {n}: {p['amplitude']:.9g} at omega = "
                             f"{p['omega']:.9g}")
        lines += [f"  fold at omega = {w:.9g}" for w in data["frc_folds"]]
    return lines


def resonant_csv(data: dict, path) -> None:
    """``--csv`` of a pair: the single-mode backbones' rows, the coupled modes', then the
    forced response's (``kind`` says which; a column that does not apply holds NaN)."""
    names = list(data["outputs"])
    nan = math.nan
    columns = (("kind", "0 a mode alone on its backbone and 1 a coupled mode and 2 a forced "
                "steady state"), ("omega", "frequency (a coupled mode: theta1')"),
               ("rho1", "normal-form amplitude of mode 1"),
               ("rho2", "normal-form amplitude of mode 2"),
               ("psi", "coupled modes only: the locked phase difference"),
               *((n, f"max |{n}| over a period") for n in names),
               ("stable", "forced response only: 1 stable and 0 not"))
    rows = []
    for f in data["families"]:
        first = f["mode"] == data["modes"][0]
        rows += [(0, p["omega"], p["rho"] if first else 0.0, 0.0 if first else p["rho"], nan,
                  *(p["amplitude"][n] for n in names), nan) for p in f["backbone"]]
    for c in data["coupled_modes"]:
        rows += [(1, p["omega"], *p["rho"], c["psi"], *(p["amplitude"][n] for n in names), nan)
                 for p in c["points"]]
    rows += [(2, q["omega"], *q["rho"], nan, *(q["amplitude"][n] for n in names),
              int(q["stable"])) for q in data.get("frc", [])]
    write_csv(path, columns, rows)


def run_resonant(args: argparse.Namespace) -> int:
    """``lindstedt ssm SYSTEM --mode M1,M2``: the 4-D SSM of two modes in internal
    resonance, its reduced dynamics; the options of one mode's SSM alone are refused."""
    from ..analysis.ssm_resonant_forced import reduce_pair

    given = [flag for flag, on in (("--exact", args.exact), ("--plot", args.plot is not None))
             if on]
    if given:
        raise InputError(f"{', '.join(given)}: not built for a mode pair (--mode "
                         f"{','.join(str(m) for m in args.mode)}); give one mode")
    if len(args.mode) > 2:
        raise InputError(f"--mode {','.join(str(m) for m in args.mode)}: give one mode, or "
                         "two in internal resonance (M1,M2); more are not built")
    _, csv = check_outputs(args)
    span = None
    if args.omega_min is not None:
        span = (args.omega_min, args.omega_max)
        if not 0 < span[0] < span[1]:
            raise InputError(f"--omega {span[0]:g}:{span[1]:g}: give 0 < A < B")
    system = _system(args.system, args.model, args.param)
    red = reduce_pair(system, args.mode, args.order,
                      _outputs(args.output, [str(x) for x in system.coordinates]),
                      args.rho_max, span)
    data = resonant_json(red)
    if csv is not None:
        resonant_csv(data, csv)
    print(json.dumps(data) if args.json else "\n".join(resonant_table(data)))
    return 0


def _system(text: str | None, folder: str | None, params, flag: str = "SYSTEM"):
    """The system of a text or a model folder (exactly one of them)."""
    from ..derive.system import parse_system, read_model

    if (text is None) == (folder is None):
        raise InputError(f"ssm: give a {flag} or --model DIR (one of them)")
    if folder is not None:
        if params:
            raise InputError("--param: a model folder holds numbers only (no parameters)")
        return read_model(folder)
    return parse_system(text, _params(params), driven=True)


def run_generate_ssm(args: argparse.Namespace) -> int:
    """``generate SYSTEM --ssm M`` (or ``--model DIR``): the reduced model's numba module and
    its LaTeX into --out."""
    import shlex

    from .. import compiler
    from ..lower.printers import identifier
    from .common import _out_folder

    if args.ssm is None:
        raise InputError("--model DIR: generate takes a model folder with --ssm M")
    given = [flag for flag, on in (
        ("--mode", args.mode is not None), ("--amplitude", args.amplitude is not None),
        ("--damped", args.damped), ("--resum-order", args.resum_order is not None),
        ("--allow-divergent", args.allow_divergent)) if on]
    if given:
        raise InputError(f"{', '.join(given)}: not for an SSM's reduced model (--ssm)")
    if args.order > SSM_MAX_ORDER or args.order < 1:
        raise InputError(f"--order {args.order}: the SSM is computed to order 1..{SSM_MAX_ORDER}")
    system = _system(args.model, args.model_dir, args.param, "SYSTEM")
    outputs = _outputs(args.output, [str(x) for x in system.coordinates])
    span = None
    if args.omega_min is not None:
        span = (args.omega_min, args.omega_max)
        if not 0 < span[0] < span[1]:
            raise InputError(f"--omega {span[0]:g}:{span[1]:g}: give 0 < A < B")
    name = identifier(args.name or f"ssm{args.ssm}")
    source = (f"--model {shlex.quote(args.model_dir)}" if args.model_dir is not None
              else f'"{args.model}"')
    command = " ".join(["lindstedt generate", source, f"--ssm {args.ssm}",
                        f"--order {args.order}", *(f"--param {p}" for p in args.param or ()),
                        *([f"--output {args.output}"] if args.output else []),
                        *([f"--omega {span[0]!r}:{span[1]!r}"] if span else []),
                        f"--name {name}"])
    paths = compiler.generate_ssm(system, args.ssm, args.order, _out_folder(args.out),
                                  name=name, command=command,
                                  outputs=None if outputs is None else tuple(outputs),
                                  span=span, overwrite_edited=args.overwrite_edited)
    for path in paths:
        print(path)
    return 0


def arguments_ssm(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt ssm``'s arguments."""
    p = sub.add_parser("ssm", help="the spectral submanifold of a mode of a damped system: "
                       "backbone, damping, forced response",
                       description="The two-dimensional spectral submanifold (SSM) of one mode "
                       "of M x'' + C x' + K x + f(x, x') = F cos(w t), by the parametrisation "
                       "method in normal-form style to order K, in floating point with sparse "
                       "matrices: its reduced dynamics rho' = rho a(rho), theta' = omega(rho), "
                       "the backbone omega(rho), the damping ratio, each output's physical "
                       "amplitude (max |x_i| over a period); with a drive, the forced response "
                       "from the reduced model (every steady state, its stability, the folds). "
                       "The system is a SYSTEM written as text (one equation per coordinate, "
                       "separated by ';') or a finite-element model's folder (--model).")
    p.add_argument("system", metavar="SYSTEM", nargs="?",
                   help="equations such as \"x1'' + 0.02*x1' + 2*x1 - x2 + x1**3 = "
                   "f*cos(w*t); x2'' + 0.02*x2' + 2*x2 - x1 = 0\" (damping, a drive "
                   "f*cos(w*t) on any equations; every name but w needs --param)")
    p.add_argument("--model", metavar="FOLDER",
                   help="a model folder instead of SYSTEM: M.mtx, K.mtx, optional C.mtx "
                   "(Matrix Market), nonlinear.txt ('i j k c' adds c*x_j*x_k to f_i, "
                   "'i j k l c' adds c*x_j*x_k*x_l; 0-based), optional drive.txt ('i F_i')")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="a value for a parameter of SYSTEM, e.g. f=1/100 (repeatable)")
    p.add_argument("--mode", type=_modes, default=(1,), metavar="M",
                   help="the mode, numbered 1, 2, … by increasing damped frequency (default "
                   "1); or two modes M1,M2 in near 1:1, 1:2 or 1:3 internal resonance: their "
                   "4-D SSM and its reduced dynamics in normal form")
    p.add_argument("--order", type=_order, default=DEFAULT_ORDER, metavar="K",
                   help=f"the SSM's order K, 1..{SSM_MAX_ORDER} (default {DEFAULT_ORDER})")
    p.add_argument("--output", metavar="LIST",
                   help="the coordinates whose amplitudes are reported, comma-separated: "
                   "0-based indices or names, e.g. 17,40 (named x17, x40 for a model; "
                   "default: every coordinate of a SYSTEM of at most 12, else the mode "
                   "shape's largest)")
    _flag_omega(p, ("A:B", "A:B:N"), "the drive frequencies of the forced response, from A "
                "to B (N points, default 500), in the system's time units (default: ±20 %% "
                "about the mode's linear frequency, where the system is driven)",
                points=FRC_POINTS)
    p.add_argument("--rho-max", type=_positive_real, default=None, metavar="R",
                   help="the backbone's end in rho (default: 0.9 of the estimated radius, or "
                   "further to the forced response's largest state inside it)")
    p.add_argument("--exact", action="store_true",
                   help="also the normal form's gamma_j exactly, in the number field of the "
                   "eigenvalues (rational data, at most 3 coordinates; the exact forms under "
                   "gamma_exact in --json, with the floating point's agreement)")
    _flag_json(p)
    _flag_plot(p)
    _flag_csv(p, "the backbone (omega, rho, damping ratio, amplitudes) and the forced "
              "response's steady states")
    _flag_allow_slow(p, deprecated_force=False)
    return p
