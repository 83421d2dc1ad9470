"""The frequency–energy plot of a system's nonlinear normal modes (each backbone from its exact
series beside orbits shot by DOP853, the series' radius, the internal-resonance lines), and a
system's energy exchange in internal resonance."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from .analysis.curves import FrequencyEnergy
from .charts import _save, _value, check_plot_path


def nnm_figure(fe: FrequencyEnergy, path: Path) -> Path:
    """Frequency against energy of every mode (an :class:`analysis.curves.FrequencyEnergy`):
    the series' backbone up to its estimated reach, orbits shot beside it (beyond the reach
    too), and dotted lines where ``n ω = ω₀`` of another mode."""
    check_plot_path(path)
    fig, ax = plt.subplots(figsize=(8, 4.8))
    for curve in fe.modes:
        if curve.note is not None:
            continue
        color = f"C{curve.mode - 1}"
        ax.plot(curve.E, curve.omega, "-", color=color, lw=2,
                label=f"mode {curve.mode}: series to order {fe.order} (ω₀ = {curve.omega0})")
        if len(curve.shots):
            ax.plot(*curve.shots.T, "o", color=color, mfc="none", ms=6,
                    label=f"mode {curve.mode}: orbits shot (DOP853)")
        ax.axvline(curve.edge, color=color, ls="--", lw=0.8,
                   label=f"mode {curve.mode}: the series' estimated reach "
                   f"(A = {_value(curve.reach)})")
    for j, n, w in fe.lines:
        ax.axhline(w, color="grey", ls=":", lw=0.8)
        ax.annotate(f"{n}ω = ω₀,{j}", (1.0, w), xycoords=("axes fraction", "data"), ha="right",
                    va="bottom", fontsize=7, color="grey")
    ax.plot([], [], ":", color="grey", label="internal resonance n ω = ω₀ of another mode")
    for curve in fe.modes:
        if curve.note is not None:
            ax.plot([], [], " ", label=curve.note)
    ax.set(xscale="log", xlabel="energy E (at the turning point, potential only)",
           ylabel="frequency ω (units of the time in the equations)",
           title="frequency–energy plot: " + fe.text[:70] + ("…" if len(fe.text) > 70 else ""))
    ax.title.set_fontsize(9)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)


def exchange_figure(flow: object, exchange: object, path: Path) -> Path:
    """A system's energy exchange (:class:`numerics.references.Exchange` of a resonant
    :class:`derive.averaging.SlowFlow`): each resonant mode's amplitude a_k over the slow
    time from ``exchange.start``, the exchange period marked between two maxima of a₁."""
    check_plot_path(path)
    fig, ax = plt.subplots(figsize=(8, 4.2))
    for k, a in enumerate(exchange.a):
        ax.plot(exchange.t, a, color=f"C{k}", lw=1.4,
                label=f"a{k + 1}: mode {flow.modes[k]} (ω₀ = {_value(float(flow.omega[k]))})")
    if np.isfinite(exchange.period):
        ax.plot([], [], " ", label=f"exchange period {_value(exchange.period)}")
    ax.set_xlabel("time t")
    ax.set_ylabel("amplitude a_k")
    ax.set_ylim(bottom=0.0)
    ax.set_title(f"{flow.system.text}\nthe averaged flow to order 1: "
                 f"{'; '.join(flow.resonances)}", fontsize=8)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=3,
              frameon=False)  # below the axes, where it hides no curve
    fig.tight_layout()
    return _save(fig, path)


def ssm_figure(data: dict, path: Path) -> Path:
    """The SSM's backbone (frequency against the first output's amplitude) with the forced
    response's steady states (stable filled, unstable hollow) and the folds, beside the
    damping ratio along the backbone — from ``ssm``'s JSON (:func:`cli.ssm.ssm_json`)."""
    check_plot_path(path)
    name = next(iter(data["outputs"]))
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.4))
    bb = data["backbone"]
    amp = np.array([p["amplitude"][name] for p in bb])
    ax.plot([p["omega"] for p in bb], amp, "-", color="C0", lw=2,
            label=f"backbone, order {data['order']}")
    frc = data.get("frc", [])
    for stable, style in ((True, dict(ms=2.5)), (False, dict(ms=3, mfc="none"))):
        pts = [(s["omega"], s["amplitude"][name]) for s in frc if s["stable"] == stable]
        if pts:
            ax.plot(*np.array(pts).T, "o", color="C1" if stable else "C3", lw=0, **style,
                    label="forced response, " + ("stable" if stable else "unstable"))
    for f in data.get("frc_folds", []):
        ax.axvline(f["omega"], color="grey", ls=":", lw=0.8)
    if data.get("frc_folds"):
        ax.plot([], [], ":", color="grey", label="folds")
    ax.set_xlabel("ω")
    ax.set_ylabel(f"max |{name}| over a period")
    ax.set_title(f"SSM of mode {data['mode']}")
    ax.legend(fontsize=8)
    bx.plot(amp, [p["damping_ratio"] for p in bb], "-", color="C0", lw=2)
    bx.set_xlabel(f"max |{name}| over a period")
    bx.set_ylabel("damping ratio ζ")
    bx.set_title("damping along the backbone")
    fig.tight_layout()
    return _save(fig, path)
