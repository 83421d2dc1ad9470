"""The figures of ``series`` and ``slowflow``: a free oscillator's ω and T against its expansion
variable, the orbit edge and the radius of convergence marked; a limit cycle's amplitude and ω
against ε; a slow flow's phase portrait.  Each draws a record of :mod:`analysis.curves` as it
is (the CSV prints the same points) and computes nothing."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from .analysis.curves import CycleCurves, Portrait, SeriesCurves
from .charts import _save, _value, check_plot_path


def _split(ax: plt.Axes, x: np.ndarray, y: np.ndarray, inside: np.ndarray, color: str,
           label: str) -> None:
    """``y(x)`` solid where ``inside``, dotted elsewhere (the partial sum past its radius)."""
    ax.plot(x, np.where(inside, y, np.nan), "-", color=color, lw=2, label=label)
    if not inside.all():
        # the dotted stretch joins the solid one: each outside point and its neighbours
        near = ~inside | np.convolve(~inside, [1, 1, 1], "same").astype(bool)
        ax.plot(x, np.where(near, y, np.nan), ":", color=color, lw=1.5,
                label="past the radius: the partial sum diverges")


def _radius_lines(ax: plt.Axes, radius: float, lo: float, hi: float, text: str) -> None:
    """Dashed lines at ``±radius`` within ``[lo, hi]``, one legend entry."""
    shown = [x for x in (-radius, radius) if lo <= x <= hi]
    for k, x in enumerate(shown):
        ax.axvline(x, color="C3", ls="--", lw=1, label=text if k == 0 else None)


def _radius_text(value: float, exact: object, spread: float, name: str) -> str:
    if exact is not None:
        return f"radius of convergence |{name}| = {exact} (exact)"
    return f"radius of convergence |{name}| ≈ {_value(value)} (estimated, spread {_value(spread)})"


def series_figure(c: SeriesCurves, path: Path) -> Path:
    """ω/ω₀ and T/(2π/ω₀) of :class:`analysis.curves.SeriesCurves` against ``y``: solid
    where the series converges and an orbit exists, dotted past the radius; the radius
    (dashed) and the orbits' edges (grey: no periodic orbit beyond) marked."""
    check_plot_path(path)
    v = c.valid
    name = c.variable.partition("=")[0].strip() or c.variable
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    inside = c.inside
    lo, hi = float(c.y[0]), float(c.y[-1])
    for ax, values, ylabel, color, what in (
            (axes[0], c.omega, "frequency ω/ω₀", "C0", "ω"),
            (axes[1], c.period, "period T/(2π/ω₀)", "C1", "T/2π")):
        _split(ax, c.y, values, inside, color, f"{what}: the series to order {c.order}")
        if v.radius is not None:
            _radius_lines(ax, v.radius, lo, hi, _radius_text(v.radius, v.exact, v.spread, name))
        edges = [x for x in (v.orbit.lower, v.orbit.upper) if math.isfinite(x)]
        for k, x in enumerate(edges):
            ax.axvline(x, color="0.4", ls="-", lw=1.5,
                       label="orbit edge: no periodic orbit beyond" if k == 0 else None)
        if v.radius is None:
            ax.plot([], [], " ", label="radius not estimated (raise --order)")
        ax.set_xlabel(f"{c.variable} (the expansion variable)")
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"{c.model}: the L–P series to order {c.order} in {c.variable}")
    fig.tight_layout()
    return _save(fig, path)


def cycle_figure(c: CycleCurves, path: Path) -> Path:
    """A limit cycle's amplitude q(0) and ω/ω₀ against ε (:class:`analysis.curves.CycleCurves`),
    dotted past the radius of ω's series, which is marked where it was estimated."""
    check_plot_path(path)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    R = c.radius.value
    inside = np.ones(c.eps.shape, bool) if R is None else np.abs(c.eps) < R
    lo, hi = float(c.eps[0]), float(c.eps[-1])
    for ax, values, ylabel, color, what in (
            (axes[0], c.amplitude, "amplitude q(0) at q'(0) = 0", "C0", "amplitude"),
            (axes[1], c.omega, "frequency ω/ω₀", "C1", "ω")):
        _split(ax, c.eps, values, inside, color, f"{what}: the series to order {c.order}")
        if R is not None:
            _radius_lines(ax, R, lo, hi, _radius_text(R, None, c.radius.spread, "ε"))
        else:
            ax.plot([], [], " ", label="radius not estimated (raise --order to 24)")
        ax.set_xlabel("ε")
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"{c.model}: its limit cycle, stable for {c.stable_for}")
    fig.tight_layout()
    return _save(fig, path)


def portrait_figure(p: Portrait, path: Path) -> Path:
    """The slow flow's phase portrait (:class:`analysis.curves.Portrait`) in van der Pol's
    plane: each trajectory from its start (a dot), the limit cycles (circles: solid
    attracting, dashed repelling) and the fixed points (filled stable, open unstable)."""
    check_plot_path(path)
    fig, ax = plt.subplots(figsize=(6.4, 6.0))
    for k, (_, x, y) in enumerate(p.trajectories):
        ax.plot(x, y, "-", color=f"C{k % 10}", lw=1, label="trajectories" if k == 0 else None)
        ax.plot(x[:1], y[:1], "o", color=f"C{k % 10}", ms=3)
    angle = np.linspace(0, 2 * np.pi, 361)
    for r, stable in sorted(p.cycles):
        ax.plot(r * np.cos(angle), r * np.sin(angle), "k-" if stable else "k--", lw=2,
                label=f"limit cycle r = {_value(r)} ({'attracting' if stable else 'repelling'})")
    for x, y, stable in p.points:
        ax.plot([x], [y], "o", color="k", mfc="k" if stable else "w", ms=7,
                label=f"fixed point ({'stable' if stable else 'unstable'})")
    w = 1.15 * p.window
    ax.set_xlim(-w, w)
    ax.set_ylim(-w, w)
    ax.set_aspect("equal")
    ax.set_xlabel("r cos φ")
    ax.set_ylabel("r sin φ")
    given = ", ".join(f"{k} = {_value(x)}" for k, x in p.values)
    frame = "q = r cos(wt + φ), w = 1 + εσ" if p.driven else "q = r cos(t + φ)"
    ax.set_title(f"{p.name}: the slow flow to order {p.order}, ε = {_value(p.eps)}"
                 + (f", {given}" if given else "") + f"\n({frame})", fontsize=9)
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles, strict=True))
    ax.legend(unique.values(), unique.keys(), fontsize=7, loc="upper right")
    fig.tight_layout()
    return _save(fig, path)
