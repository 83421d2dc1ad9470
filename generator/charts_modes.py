"""The frequency–energy plot of a system's nonlinear normal modes (each backbone from its exact
series beside orbits shot by DOP853, the series' radius, the internal-resonance lines), and a
driven system's response curves."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from .analysis.curves import FEP_MAX_MODES, FrequencyEnergy
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


def response_system_figure(r: object, path: Path) -> Path:
    """A driven system's response (:class:`analysis.systems.SystemResponse`): one panel per
    coordinate (at most :data:`FEP_MAX_MODES`), its first-harmonic amplitude over ω along
    every traced branch, stable solid and unstable dashed, the folds, the sweeps' jumps as
    arrows, the points shot as true orbits as circles, the linear ω₀ as dotted lines."""
    check_plot_path(path)
    names = [str(x) for x in r.system.coordinates][:FEP_MAX_MODES]
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 2.6 * len(names) + 0.6), sharex=True,
                             squeeze=False)
    pieces = r.cont.piece_slices()
    for i, (ax, name) in enumerate(zip(axes[:, 0], names, strict=True)):
        for k, piece in enumerate(pieces):
            w, a, s = r.cont.omega[piece], r.amplitudes[piece, i], r.stable[piece]
            for flag, style in ((True, "-"), (False, "--")):
                shown = np.where(s == flag, a, np.nan)
                # a stretch's ends meet the next one's: no gap at a change of stability
                edge = np.nonzero(np.diff(s.astype(int)))[0]
                shown[edge + (0 if flag else 1)] = a[edge + (0 if flag else 1)]
                shown[edge + (1 if flag else 0)] = a[edge + (1 if flag else 0)]
                ax.plot(w, shown, style, color=f"C{k % 10}", lw=1.6 if flag else 1.0,
                        label=(f"branch {k + 1}" + (" (isola)" if r.closed[k] else "")
                               + (": stable" if flag else ": unstable (Floquet |λ| > 1)")))
        for c in r.checks:
            if c.shot:
                ax.plot(c.omega, c.shot[i], "o", mfc="none", mec="k", ms=6,
                        label="orbit shot (DOP853)")
        for w in r.cont.folds:
            ax.axvline(w, color="grey", lw=0.5, ls="-", alpha=0.5)
        for w in r.linear_frequencies:
            ax.axvline(w, color="grey", lw=0.8, ls=":")
        for way, w, before, after in r.jumps:
            ax.annotate("", xy=(w, r.amplitudes[after, i]), xytext=(w, r.amplitudes[before, i]),
                        arrowprops={"arrowstyle": "->", "color": "C3" if way == "up" else "C4",
                                    "lw": 1.2})
            ax.plot([], [], "-", color="C3" if way == "up" else "C4",
                    label=f"sweep {way}: jump")
        ax.set_ylabel(f"r of {name}")
        if i == 0:
            ax.plot([], [], ":", color="grey", label="linear ω₀")
            ax.plot([], [], "-", color="grey", lw=0.5, label="fold")
            handles, labels = ax.get_legend_handles_labels()
            unique = dict(zip(labels, handles, strict=True))
    # the legend below the panels, where it hides no curve
    fig.legend(unique.values(), unique.keys(), fontsize=7, loc="lower center",
               ncol=min(4, len(unique)), frameon=False)
    axes[-1, 0].set_xlabel(f"drive frequency {r.system.frequency} (ω)")
    title = r.system.text if len(r.system.text) <= 90 else r.system.text[:89] + "…"
    axes[0, 0].set_title(f"response: {title}", fontsize=8)
    rows = -(-len(unique) // min(4, len(unique)))
    fig.tight_layout(rect=(0, 0.035 * rows + 0.01, 1, 1))
    return _save(fig, path)


def exchange_figure(flow: object, exchange: object, path: Path) -> Path:
    """A system's energy exchange (:class:`numerics.references.Exchange` of a
    :class:`derive.resonance.ResonantFlow`): each resonant mode's amplitude a_k over the slow
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
