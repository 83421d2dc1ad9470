"""Figures (matplotlib, Agg): response curve with hysteresis, subharmonic region, mixing spectrum.

Each function computes nothing new: it draws what :mod:`response` and :mod:`numerics` return,
and writes the file atomically (a temporary file in the target folder, then a rename).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from .choose import (
    DRIVEN_QUANTITIES,
    DrivenTradeoff,
    candidates,
    driven_tradeoffs,
    driven_truth,
    pareto_front,
    reference_period,
    tradeoffs,
)
from .driven import Drive, amplitudes, first_order_branches, harmonic_balance, mu_expansion
from .errors import InputError
from .numerics import steady_state_amplitudes, sweep
from .response import (
    continue_balance,
    mixing_tones,
    one_harmonic_curve,
    one_harmonic_folds,
    subharmonic,
    tone_label,
)

FORMATS = (".png", ".svg", ".pdf")
METADATA = {".png": {"Software": None}, ".svg": {"Date": None}, ".pdf": {"CreationDate": None}}
# NOTE: no software version or date in the files: the same command writes the same bytes.


def check_plot_path(path: Path) -> Path:
    """A writable figure path with a known format, or :class:`InputError` (nothing written)."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise InputError(f"--plot {path}: use one of {', '.join(FORMATS)}")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir() or not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"--plot {path}: folder {folder} does not exist or is not writable")
    return path


def _save(fig: plt.Figure, path: Path) -> Path:
    path = check_plot_path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=110, metadata=METADATA[path.suffix.lower()])
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        Path(tmp).unlink(missing_ok=True)
    return path


def response_figure(eps: float, force: float, Q: float, harmonics: int, path: Path) -> Path:
    """Response r(ω): one-harmonic branches (stable solid, unstable dashed), N-harmonic
    continuation, simulated sweeps up and down, folds; and the linear curves of Fig. 1."""
    check_plot_path(path)
    folds = one_harmonic_folds(eps, force, Q)
    lo, hi = 0.5 * min([1.0, *folds]), 1.25 * max([1.0, *folds])
    omega = np.linspace(lo, hi, 2000)
    curve = one_harmonic_curve(eps, force, Q, omega)
    cont = continue_balance(eps, force, Q, harmonics, lo, hi)
    up, down = sweep(eps, force, 1 / Q, lo, hi), sweep(eps, force, 1 / Q, hi, lo)
    fig, (ax, lin) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [3, 2]})
    count = np.isfinite(curve.r).sum(axis=1)
    jumps = np.concatenate([[False], count[1:] != count[:-1]])  # branches appear/vanish here
    for k in range(3):
        r = np.where(jumps, np.nan, curve.r[:, k])
        ax.plot(omega, np.where(curve.stable[:, k], r, np.nan), "C0-", lw=2,
                label="one harmonic, stable" if k == 0 else None)
        ax.plot(omega, np.where(~curve.stable[:, k], r, np.nan), "C0--", lw=1.5,
                label="one harmonic, unstable" if k == 1 else None)
    amp = np.hypot(cont.x[:, 0], cont.x[:, harmonics])
    ax.plot(cont.omega, amp, "k-", lw=0.7, label=f"harmonic balance N = {harmonics}")
    ax.plot(up.omega, up.amplitude, "C3.", ms=1.5, label="sweep up (max |q|)")
    ax.plot(down.omega, down.amplitude, "C2.", ms=1.5, label="sweep down (max |q|)")
    for w in cont.folds:
        ax.axvline(w, color="grey", ls=":", lw=1)
    ax.set(xlabel="drive frequency ω", ylabel="amplitude",
           title=f"q̈ + q̇/Q + q + εq³ = f cos ωt  (ε = {eps}, f = {force}, Q = {Q})")
    ax.legend(fontsize=8, loc="upper left")
    w = np.linspace(0.5, 1.5, 1000)
    for i, q in enumerate((2, 5, 10)):
        lin.plot(w, 1 / np.sqrt((1 - w**2) ** 2 + w**2 / q**2), f"C{i}-", label=f"Q = {q} (3.79)")
        lin.plot(w, 1 / np.sqrt(4 * (1 - w) ** 2 + 1 / q**2), f"C{i}:", label=f"Q = {q} (3.83)")
    lin.set(xlabel="ω", ylabel="|q| / f", title="linear oscillator (notes' Fig. 1)")
    lin.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def subharmonic_figure(eps: float, force: float, path: Path) -> Path:
    """Amplitude a(ω) of both roots of eq. 10.87 where they exist; Hill verdict as line
    style, the true orbit's verdict as markers."""
    check_plot_path(path)
    omega = np.linspace(1.0, 2.0, 161)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for sign, color in (("+", "C0"), ("-", "C3")):
        a, hill, true_w, true_a, true_s = [], [], [], [], []
        for w in omega:
            exists, _, sols = subharmonic(eps, force, float(w))
            s = next((s for s in sols if s.root == sign), None) if exists else None
            a.append(np.nan if s is None else s.a)
            hill.append(bool(s and s.hill_stable))
            if s is not None and s.orbit is not None and round(w * 160) % 8 == 0:
                true_w.append(w), true_a.append(s.orbit.A[1]), true_s.append(s.orbit.stable)
        a, hill = np.array(a), np.array(hill)
        ax.plot(omega, np.where(hill, a, np.nan), f"{color}-", lw=2,
                label=f"root {sign}, Hill stable")
        ax.plot(omega, np.where(~hill, a, np.nan), f"{color}--", lw=1.5,
                label=f"root {sign}, Hill unstable")
        ts = np.array(true_s, dtype=bool)
        ax.plot(np.array(true_w)[ts], np.array(true_a)[ts], f"{color}o", ms=5, mfc="none")
        ax.plot(np.array(true_w)[~ts], np.array(true_a)[~ts], f"{color}x", ms=5)
    ax.axhline(0, color="grey", lw=0.5)
    ax.set(xlabel="ω (drive at 3ω)", ylabel="a, first harmonic",
           title=f"1/3 subharmonic (ε = {eps}, f = {force}); o stable, x unstable true orbit")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


def mixing_figure(eps: float, Q: float, drives: list[tuple[float, float]], path: Path) -> Path:
    """Spectrum of the steady state: predicted tones (stems) and simulated amplitudes."""
    check_plot_path(path)
    tones = mixing_tones(eps, Q, drives)
    sim = steady_state_amplitudes(eps, 1 / Q, [f for f, _ in drives], [w for _, w in drives],
                                  [t.frequency for t in tones])
    fig, ax = plt.subplots(figsize=(8, 4.2))
    for t, s in zip(tones, sim, strict=True):
        ax.vlines(t.frequency, 1e-8, t.predicted, color=f"C{t.order}", lw=2)
        ax.plot(t.frequency, s, "kx", ms=6)
        if t.order <= 1:
            ax.annotate(tone_label(t.combination), (t.frequency, t.predicted),
                        textcoords="offset points", xytext=(0, 4), ha="center", fontsize=7)
    for order in range(3):
        ax.plot([], [], f"C{order}-", lw=2, label=f"predicted, order {order}")
    ax.plot([], [], "kx", label="simulated steady state")
    ax.set_yscale("log")
    ax.set_ylim(1e-7, 2)
    ax.set(xlabel="frequency", ylabel="amplitude",
           title=f"frequency mixing (ε = {eps}, Q = {Q}, drives "
                 + ", ".join(f"{f}@{w}" for f, w in drives) + ")")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


GALLERY = (
    ("response.png", lambda path: response_figure(0.1, 0.3, 20.0, 8, path)),
    ("subharmonic.png", lambda path: subharmonic_figure(0.1, 0.5, path)),
    ("mixing.png", lambda path: mixing_figure(0.1, 10.0, [(0.3, 1.3), (0.3, 1.7)], path)),
    ("validity.png", lambda path: validity_figure(path)),
    ("driven_validity.png", lambda path: driven_validity_figure(path)),
)
# NOTE: the figures the README shows whose content is pure computation (no measured time):
# the demo draws them into its --out, `make figures` into docs/figures, byte-identical each run.


def gallery(folder: Path) -> list[Path]:
    """Draw every figure of :data:`GALLERY` into ``folder`` (created if missing)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name, _ in GALLERY:
        check_plot_path(folder / name)
    return [draw(folder / name) for name, draw in GALLERY]

CHART_X = (0.1, 0.5, 0.9, 5.0, 100.0)
# NOTE: representative εA²: weak, moderate, near the L–P radius, strong, very strong springs.
FLOOR = 1e-17
# NOTE: errors below double precision are drawn at this floor (log axes).


def speed_accuracy_figure(path: Path) -> Path:
    """Error against measured cost, one point per method and order, per x; Pareto fronts.
    Bottom row: the compiled evaluators alone (0.3–40 ns), where the choice is made."""
    check_plot_path(path)
    data = tradeoffs(np.array(CHART_X))
    fig, axes = plt.subplots(2, len(CHART_X), figsize=(16, 7), sharey=True)
    colors = {"lindstedt": "C0", "resummed": "C1", "pade": "C2", "modified": "C3",
              "agm": "C5", "exact": "k", "numerical": "C4"}
    cost = np.array([t.ns_per_point for t in data])
    for k, x in enumerate(CHART_X):
        err = np.maximum(np.array([t.errors[k] for t in data]), FLOOR)
        front = pareto_front(cost, err)
        for row, ax in enumerate(axes[:, k]):
            for method, color in colors.items():
                sel = [i for i, t in enumerate(data) if t.method == method]
                ax.plot(cost[sel], err[sel], "o", color=color, ms=3, label=method)
            ax.plot(cost[front], err[front], "r-", lw=1, label="Pareto front")
            ax.set(xscale="log", yscale="log", xlabel="ns / point")
            if row == 0:
                ax.set_title(f"x = εA² = {x:g}")
            else:
                ax.set_xlim(0.3, 40)
    for ax in axes[:, 0]:
        ax.set_ylabel("relative error of T")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


DRIVEN_CHART_OMEGA = (0.5, 1.0, 1.6, 2.5)
# NOTE: the notes' ε = 0.1, f = 1: below, at, and above the linear resonance, and beyond the
# fold at ω ≈ 1.34 where only the large branch is followed.


def driven_speed_accuracy_figure(path: Path, eps: float = 0.1, force: float = 1.0,
                                 Q: float = np.inf, extra: Sequence[DrivenTradeoff] = ()) -> Path:
    """Error of A_n (n = 1, 3, 5) and of r against the true orbit versus measured cost per
    ω: one harmonic, μ-expansion orders 0..12, harmonic balance 1..12, shooting with plain
    RK4, and ``extra`` points at the same ω (the benchmark's emitted modules); Pareto fronts."""
    check_plot_path(path)
    truth = driven_truth(eps, force, Q, np.array(DRIVEN_CHART_OMEGA))
    data = driven_tradeoffs(truth, eps, force, Q) + list(extra)
    cost = np.array([t.ns_per_point for t in data]) / 1e3
    colors = {"one_harmonic": "C3", "mu_expansion": "C0", "harmonic_balance": "C2",
              "shooting": "C4", "mu_expansion, emitted": "C9",
              "harmonic_balance, emitted": "C8"}
    fig, axes = plt.subplots(2, len(DRIVEN_CHART_OMEGA), figsize=(15, 6.5), sharex=True,
                             sharey=True)
    for row, quantity in enumerate(DRIVEN_QUANTITIES):
        for k, w in enumerate(DRIVEN_CHART_OMEGA):
            ax = axes[row, k]
            err = np.maximum(np.array([t.errors[quantity][k] for t in data]), FLOOR)
            for method, color in colors.items():
                sel = [i for i, t in enumerate(data) if t.method == method]
                ax.plot(cost[sel], err[sel], "o", color=color, ms=3, label=method)
            front = pareto_front(cost, err)
            ax.plot(cost[front], err[front], "r-", lw=1, label="Pareto front")
            ax.set(xscale="log", yscale="log", title=f"{quantity}, ω = {w:g}")
            if row == 1:
                ax.set_xlabel("µs per ω (measured)")
        axes[row, 0].set_ylabel("max |A_n − A_n,true|" if quantity == "amplitudes"
                                else "|r − r_true|")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(f"driven Duffing ε = {eps}, f = {force}" + ("" if np.isinf(Q) else f", Q = {Q}")
                 + ": error against the true orbit (shooting) versus cost", fontsize=10)
    fig.tight_layout()
    return _save(fig, path)


def validity_figure(path: Path) -> Path:
    """Error against x from the separatrix to εA² = 10³ for chosen orders of each method."""
    check_plot_path(path)
    x = np.concatenate([-1 + np.logspace(-3, np.log10(0.999), 200), np.logspace(-3, 3, 300)])
    x = np.unique(x[x < 1000])
    ref = reference_period(x)
    picks = (("lindstedt", 4), ("lindstedt", 12), ("lindstedt", 40), ("resummed", 10),
             ("resummed", 21), ("resummed", 40), ("pade", 4), ("pade", 12), ("modified", 4),
             ("modified", 12), ("agm", 2), ("agm", 4))
    styles = {"lindstedt": "-", "resummed": "--", "pade": ":", "modified": "-.", "agm": "-"}
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for c in candidates():
        if (c.method, c.order) in picks:
            with np.errstate(invalid="ignore"):
                err = np.maximum(np.abs(c(x) / ref - 1), FLOOR)
            ax.plot(x, err, styles[c.method], lw=1.2, label=f"{c.method} {c.order}",
                    color=plt.cm.tab20(picks.index((c.method, c.order))))
    for xv, text in ((-1, "separatrix x = −1"), (1, "L–P radius |x| = 1"),
                     (-2 / 3, "m = −1: resummed limit")):
        ax.axvline(xv, color="grey", lw=0.8, ls="-.")
        ax.annotate(text, (xv, 1e-15), rotation=90, fontsize=7, va="bottom", ha="right")
    ax.set(xscale="symlog", yscale="log", ylim=(FLOOR / 2, 10), xlim=(-1.05, 1000),
           xlabel="x = εA² (symlog)",
           ylabel="relative error of T", title="where each method holds (NaN = refused)")
    ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    return _save(fig, path)


VALIDITY_METHODS = (("mu_expansion", 1), ("mu_expansion", 2), ("mu_expansion", 4),
                    ("mu_expansion", 6), ("mu_expansion", 10), ("harmonic_balance", 2),
                    ("harmonic_balance", 4))
# NOTE: what the driven validity map draws; harmonic balance with 10 harmonics is the judge.


def _validity_errors(d: Drive) -> tuple[np.ndarray, int]:
    """|A₁ − A₁(balance, N = 10)| on the largest branch for each of VALIDITY_METHODS (NaN
    where it refuses: a fold, a diverging or stalled μ-series, a balance that does not
    converge), and the branch count."""
    branches = first_order_branches(d)
    truth = amplitudes(harmonic_balance(d, branches[0], 10).coefficients, 0.0, 1)[0][1]
    errors = np.full(len(VALIDITY_METHODS), np.nan)
    for k, (method, order) in enumerate(VALIDITY_METHODS):
        if method == "mu_expansion":
            mu = mu_expansion(d, branches[0], order)
            if len(mu.coefficients) > order and mu.converged:
                errors[k] = abs(amplitudes(*mu.partial(order), 1)[0][1] - truth)
        else:
            hb = harmonic_balance(d, branches[0], order)
            if hb.converged:
                errors[k] = abs(amplitudes(hb.coefficients, 0.0, 1)[0][1] - truth)
    return errors, len(branches)


def driven_validity_figure(path: Path, eps: float = 0.1, force: float = 1.0) -> Path:
    """Where the driven-oscillator formulas hold: the μ-expansion's and low-order harmonic
    balance's error against harmonic balance (N = 10, equal to the true orbit to ~1e-10) on
    the largest branch over ω and over f, with the folds where branches appear; and the
    region of ω, f where the 1/3 subharmonic exists."""
    check_plot_path(path)
    fig, (ax, byf, sub) = plt.subplots(1, 3, figsize=(17, 4.2))
    for axis, grid, label, make in (
            (ax, np.linspace(0.3, 2.5, 221), "ω", lambda v: Drive(eps, force, float(v))),
            (byf, np.logspace(-2, 1.2, 161), "f", lambda v: Drive(eps, float(v), 0.6))):
        rows = [_validity_errors(make(v)) for v in grid]
        errors = np.array([r[0] for r in rows])
        counts = np.array([r[1] for r in rows])
        for k, (method, order) in enumerate(VALIDITY_METHODS):
            name = (f"μ-expansion order {order}" if method == "mu_expansion"
                    else f"harmonic balance N = {order}")
            axis.plot(grid, np.maximum(errors[:, k], FLOOR), "--" * (method != "mu_expansion")
                      or "-", label=name)
        for i in np.nonzero(np.diff(counts))[0]:
            axis.axvline(grid[i + 1], color="grey", ls=":", lw=1)
        axis.set(yscale="log", xlabel=label, ylabel="|A₁ − A₁(balance, N = 10)|")
    ax.set_title(f"over ω (ε = {eps}, f = {force}); dotted: folds", fontsize=9)
    byf.set(xscale="log")
    byf.set_title(f"over f (ε = {eps}, ω = 0.6): gaps = refused (not converging)", fontsize=9)
    ax.legend(fontsize=7)
    w = np.linspace(1.0, 2.5, 400)
    for e in (0.05, 0.1, 0.3):
        f_max = np.abs(1 - 9 * w**2) * np.sqrt(np.maximum(16 * (w**2 - 1) / (21 * e), 0))
        sub.plot(w, f_max, label=f"ε = {e}")
    sub.set(yscale="log", ylim=(1e-2, 1e3), xlabel="ω (drive at 3ω)", ylabel="f",
            title="1/3 subharmonic exists below each curve (eq. 10.87)")
    sub.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


SWEEP_AXES = ("omega", "force", "eps", "Q")
# NOTE: the grid axes of lindstedt.sweep (every other dimension of a field is drawn at its last
# entry: the highest order, the last branch or root).
SWEEP_CUTS = 5
# NOTE: at most five cuts along the first axis: more lines than that cannot be told apart.


def sweep_figure(ds: object, path: Path) -> Path:
    """A finished sweep (the xarray Dataset of :func:`lindstedt.sweep.run_sweep`): its
    headline field (``ds.attrs["headline"]``) as a map over the first two axes that have more
    than one value (further axes at their first value), beside cuts along the first axis at up
    to :data:`SWEEP_CUTS` values of the second; one axis: a curve. Errors on a log scale;
    counts and flags of −1 (none) left blank."""
    check_plot_path(path)
    done = ds["done"].values
    if not done.all():
        raise InputError(f"sweep figure: {int(done.sum())} of {done.size} blocks are done; "
                         "resume the sweep first")
    name = ds.attrs["headline"]
    field = ds[name]
    extra = [d for d in field.dims if d not in SWEEP_AXES]
    picked = [f"{d} = {ds[d].values[-1]}" for d in extra if d in ds.coords]
    field = field.isel({d: -1 for d in extra})
    varying = [a for a in field.dims if field.sizes[a] > 1]
    field = field.isel({a: 0 for a in field.dims if a not in varying[:2]})
    values = field.values.astype(float)
    values[values < 0] = np.nan  # −1: no branch, no orbit, not computed
    log = name.endswith("error")
    if log:
        values = np.maximum(values, FLOOR)
    fixed = ", ".join([*picked, *(f"{a} = {ds[a].values[0]:g}" for a in SWEEP_AXES
                                  if a in ds.dims and a not in varying[:2])])
    label = field.attrs.get("long_name", name)

    def positions(axis: str) -> tuple[np.ndarray, bool]:
        """Coordinates to draw at (indices where Q = inf is among them), and a log axis?"""
        v = ds[axis].values.astype(float)
        if not np.all(np.isfinite(v)):
            return np.arange(v.size, dtype=float), False
        return v, bool(v.min() > 0 and v.max() / v.min() > 20)

    def ticks(ax: plt.Axes, axis: str, which: str) -> None:
        v = ds[axis].values
        if not np.all(np.isfinite(v)):
            getattr(ax, f"set_{which}ticks")(np.arange(v.size), [f"{x:g}" for x in v])

    if len(varying) >= 2:
        xa, ya = varying[:2]
        (x, xlog), (y, ylog) = positions(xa), positions(ya)
        grid = values.reshape(field.sizes[xa], field.sizes[ya]).T
        fig, (ax, cuts) = plt.subplots(1, 2, figsize=(12, 4.4))
        mesh = ax.pcolormesh(x, y, np.log10(grid) if log else grid, shading="nearest",
                             cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=f"log10 {name}" if log else name)
        ax.set(xscale="log" if xlog else "linear", yscale="log" if ylog else "linear",
               xlabel=xa, ylabel=ya)
        ticks(ax, xa, "x"), ticks(ax, ya, "y")
        for j in np.unique(np.linspace(0, y.size - 1, min(SWEEP_CUTS, y.size)).round()):
            cuts.plot(x, grid[int(j)], ".-", ms=3, label=f"{ya} = {ds[ya].values[int(j)]:g}")
        cuts.legend(fontsize=8)
        cuts.set(xscale="log" if xlog else "linear", yscale="log" if log else "linear",
                 xlabel=xa, ylabel=name)
        ticks(cuts, xa, "x")
    else:
        fig, cuts = plt.subplots(figsize=(7, 4.4))
        xa = varying[0] if varying else next(a for a in SWEEP_AXES if a in field.dims)
        x, xlog = positions(xa)
        if not varying:
            x = x[:1]
        cuts.plot(x, values.ravel(), "o-", ms=3)
        cuts.set(xscale="log" if xlog else "linear", yscale="log" if log else "linear",
                 xlabel=xa, ylabel=name)
        ticks(cuts, xa, "x")
    fig.suptitle(f"{ds.attrs['kind']} sweep: {label}" + (f"  ({fixed})" if fixed else ""),
                 fontsize=10)
    fig.tight_layout()
    return _save(fig, path)
