"""Figures: written atomically, byte-reproducible, bad paths refused before any work."""

from __future__ import annotations

import importlib
import itertools

import numpy as np
import pytest
from lindstedt import charts, cli
from lindstedt.analysis.mixing import duffing_mixing
from lindstedt.charts import check_plot_path, mixing_figure
from lindstedt.errors import InputError
from matplotlib.colors import to_rgba
from scipy.integrate import solve_ivp

MIX_EPS, MIX_Q, MIX_DRIVES = 0.1, 10.0, [(0.3, 1.3), (0.3, 1.7)]


def true_spectrum(eps, Q, drives, base, samples=4096):
    """Amplitudes of the tones k·base of the simulated steady state (DOP853, rtol 1e-11): both
    drives are multiples of ``base``, so the steady state repeats after 2π/base and one FFT
    over that period gives every tone exactly (after 40Q of transients)."""
    def rhs(t, y):
        return [y[1], -y[1] / Q - y[0] - eps * y[0] ** 3
                + sum(f * np.cos(w * t) for f, w in drives)]

    period, settle = 2 * np.pi / base, 40 * Q
    sol = solve_ivp(rhs, (0, settle + period), [0.0, 0.0], method="DOP853", rtol=1e-11,
                    atol=1e-13, dense_output=True)
    q = sol.sol(settle + np.arange(samples) * period / samples)[0]
    return 2 * np.abs(np.fft.rfft(q)) / samples


def test_mixing_figure_draws_the_true_spectrum(tmp_path, monkeypatch):
    """The figure's content: a stem at every tone ±ω₁±ω₂… a cubic force makes to second
    order (3 and 5 factors), coloured by the order it first appears at, as tall as the
    steady state's tone (an independent simulation: within the next order); a cross at the
    simulated amplitude.  Then: a PNG, no temporary left, the same bytes on a second run."""
    drawn = []
    save = charts._save
    monkeypatch.setattr(charts, "_save", lambda fig, path: (drawn.append(fig), save(fig, path))[1])
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    mixing_figure(duffing_mixing(MIX_EPS, MIX_Q, MIX_DRIVES), a, "eps = 0.1")
    (fig,) = drawn
    (ax,) = fig.axes
    # every combination m₁ω₁ + m₂ω₂ of 3 or 5 drive factors, in units of 0.1 (ω = 1.3, 1.7)
    expected = {}
    for factors in (1, 3, 5):
        for combo in itertools.product((13, -13, 17, -17), repeat=factors):
            k = sum(combo)
            if k > 0:
                expected.setdefault(k, (factors - 1) // 2)  # the lowest order: 0, 1, 2
    stems = {}
    for coll in ax.collections:
        (seg,) = coll.get_segments()
        (x0, y0), (x1, y1) = seg
        assert x0 == x1 and y0 == 1e-8
        stems[round(x0 * 10)] = (x0, y1, tuple(coll.get_colors()[0]))
    assert sorted(stems) == sorted(expected)
    truth = true_spectrum(MIX_EPS, MIX_Q, MIX_DRIVES, 0.1)
    tolerance = {0: 1e-3, 1: 2e-2, 2: 0.3}  # relative: the first omitted order, ~ρ³
    for k, (x, height, color) in stems.items():
        order = expected[k]
        assert x == pytest.approx(k / 10, abs=1e-12)
        assert color == to_rgba(f"C{order}"), (k, order)
        assert abs(height / truth[k] - 1) < tolerance[order], (k, height, truth[k])
    crosses = [line for line in ax.lines if line.get_marker() == "x" and len(line.get_xdata())]
    assert len(crosses) == len(expected)
    for line in crosses:
        (x,), (y,) = line.get_xdata(), line.get_ydata()
        k = round(x * 10)
        assert abs(y - truth[k]) < 1e-3 * truth[k] + 5e-10, (k, y, truth[k])  # the fit
    assert ax.get_yscale() == "log"
    assert a.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    mixing_figure(duffing_mixing(MIX_EPS, MIX_Q, MIX_DRIVES), b, "eps = 0.1")
    assert a.read_bytes() == b.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]  # no temporaries


@pytest.mark.parametrize("bad", ["out.jpg", "/no/such/folder/x.png", "noext"])
def test_bad_plot_paths(bad):
    with pytest.raises(InputError):
        check_plot_path(bad)


class Computed(Exception):
    """Raised by the stand-in for a command's computation."""


@pytest.mark.parametrize("args,where,compute", [
    (["response", "--eps", "0.1", "--force", "0.3", "--Q", "20"], "cli.response",
     "response_report"),
    (["subharmonic", "--eps", "0.1", "--force", "0.5", "--omega", "1.2"],
     "analysis.subharmonic", "subharmonic"),
    (["mixing", "--eps", "0.1", "--Q", "10", "--drive", "0.3@1.3"], "analysis.mixing",
     "duffing_mixing"),
])
def test_cli_refuses_bad_plot_path_before_computing(tmp_path, monkeypatch, capsys, args,
                                                    where, compute):
    """The computation is replaced by a stand-in that records its call and raises: with a
    good --plot the command reaches it, with a bad one it answers 2 without calling it."""
    calls = []

    def stand_in(*a, **kw):
        calls.append(a)
        raise Computed

    monkeypatch.setattr(importlib.import_module(f"lindstedt.{where}"), compute, stand_in)
    with pytest.raises(Computed):  # a writable figure path: the command computes
        cli.main([*args, "--plot", str(tmp_path / "ok.png")])
    assert len(calls) == 1
    calls.clear()
    capsys.readouterr()
    for bad in (tmp_path / "x.gif", tmp_path / "no" / "x.png"):
        assert cli.main([*args, "--plot", str(bad)]) == 2
        out = capsys.readouterr()
        assert out.out == "" and "--plot" in out.err and len(out.err.splitlines()) == 1
        assert calls == []  # refused before any computation
    assert list(tmp_path.iterdir()) == []


def test_subharmonic_figure_marks_the_full_hill_verdict(tmp_path, monkeypatch):
    """Small markers on each root's curve give the full Hill verdict every FULL_HILL_EVERY ω
    (dot stable, triangle unstable); where it parts from the notes' q₀ test (the line style)
    it is the true orbit's Floquet verdict (shooting from the balance orbit, RK4 monodromy)."""
    from lindstedt.analysis.curves import subharmonic_curve
    from lindstedt.analysis.subharmonic import subharmonic

    drawn = []
    save = charts._save
    monkeypatch.setattr(charts, "_save", lambda fig, path: (drawn.append(fig), save(fig, path))[1])
    charts.subharmonic_figure(subharmonic_curve(0.1, 0.5), tmp_path / "s.png")
    (fig,) = drawn
    (ax,) = fig.axes
    marks = {line.get_label(): line for line in ax.lines if "full Hill" in line.get_label()}
    assert sorted(marks) == [f"root {s}, full Hill {v}" for s in "+-"
                             for v in ("stable", "unstable")]
    assert {marks[k].get_marker() for k in marks} == {".", "v"}
    parted = []
    for sign in "+-":
        for verdict in ("stable", "unstable"):
            line = marks[f"root {sign}, full Hill {verdict}"]
            for w, a in zip(line.get_xdata(), line.get_ydata(), strict=True):
                _, _, sols = subharmonic(0.1, 0.5, float(w))
                s = next(s for s in sols if s.root == sign)
                assert a == s.a
                if s.hill_stable != (verdict == "stable"):
                    parted.append((sign, verdict, s))
    assert parted  # the q₀ test and the full one disagree somewhere on 1 ≤ ω ≤ 2
    checked = [(sign, verdict, s) for sign, verdict, s in parted if s.orbit is not None]
    assert checked
    for sign, verdict, s in checked[:4]:
        assert s.orbit.stable == (verdict == "stable"), (sign, verdict, s.a)


def _drawn(monkeypatch):
    """The figures handed to ``_save`` (they are still written)."""
    drawn = []
    save = charts._save
    monkeypatch.setattr(charts, "_save", lambda fig, path: (drawn.append(fig), save(fig, path))[1])
    return drawn


def _texts(fig):
    """Every legend entry and title of ``fig``."""
    out = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    out += [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    return out + [ax.get_title() for ax in fig.axes] + [fig._suptitle.get_text()
                                                        if fig._suptitle else ""]


def _digits_ok(texts):
    """No number in ``texts`` with more than three significant digits."""
    import re

    for text in texts:
        for number in re.findall(r"\d+\.\d+|\d+", text):
            assert len(number.replace(".", "").lstrip("0")) <= 3, (number, text)


def test_response_figure_labels_and_settled_sweeps(tmp_path, monkeypatch):
    """The response chart: ω/ω₀ and r on the axes, the folds and the Floquet verdicts in the
    legend, and every sweep point drawn as data is a steady state — within 0.5 % of the
    max |q| of an orbit of the continued harmonic balance at its ω (interpolated along each
    monotone stretch of the curve) — while the start-up and jump transients are drawn apart
    as "not settled"."""
    from lindstedt.analysis.systems import notes_problem, response

    de, closed = notes_problem(0.1, 0.3, 20.0)
    r = response(de, 8, closed=closed)
    drawn = _drawn(monkeypatch)
    charts.response_figure(r, tmp_path / "r.png")
    (fig,) = drawn
    ax = fig.axes[0]
    assert "ω/ω₀" in ax.get_xlabel() and "r" in ax.get_ylabel() and "max |q|" in ax.get_ylabel()
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert {"fold", "sweep not settled (transient)", "branch 1: stable",
            "branch 1: unstable (Floquet |λ| > 1)", "one harmonic, stable (r)"} <= set(labels)
    assert "f = 0.3" in ax.get_title() and "Q = 20" in ax.get_title()
    _digits_ok(_texts(fig))
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    stretches = []
    for piece in r.cont.piece_slices():
        w = r.cont.omega[piece]
        top = [np.max(np.abs(sum(A[k] * np.cos(k * t) + B.get(k, 0.0) * np.sin(k * t)
                                 for k in A))) for A, B in map(r.fine.amplitudes, r.cont.x[piece])]
        turns = np.nonzero(np.diff(np.sign(np.diff(w))))[0] + 1
        for a, b in zip([0, *turns], [*turns, len(w) - 1], strict=True):
            order = np.argsort(w[a:b + 1])
            stretches.append((w[a:b + 1][order], np.array(top[a:b + 1])[order]))
    sweeps = [line for line in ax.lines if line.get_label().startswith("simulated sweep")]
    assert len(sweeps) == 2
    for line in sweeps:
        for w, a in zip(line.get_xdata(), line.get_ydata(), strict=True):
            steady = [np.interp(w, x, y) for x, y in stretches if x[0] <= w <= x[-1]]
            assert min(abs(a / s - 1) for s in steady) < 5e-3, (w, a)
    (rest,) = [line for line in ax.lines if line.get_label().startswith("sweep not settled")]
    assert max(rest.get_ydata()) > 0.7  # the start-up spike at ω = 0.5 is among them


def test_validity_figure_separates_orders_and_hides_rounding(tmp_path, monkeypatch):
    """One panel per method, its orders in distinct colours; nothing drawn below ROUNDING
    (the shaded band says so); every line style in a legend."""
    drawn = _drawn(monkeypatch)
    charts.validity_figure(tmp_path / "v.png")
    (fig,) = drawn
    for ax in fig.axes:
        curves = [line for line in ax.lines if line.get_label().startswith("order")]
        assert len({line.get_color() for line in curves}) == len(curves) >= 2
        for line in curves:
            y = np.asarray(line.get_ydata(), dtype=float)
            assert not (y[np.isfinite(y)] < charts.ROUNDING).any()
    legend = {t.get_text() for t in fig.legends[0].get_texts()}
    assert any("rounding" in text for text in legend)
    assert {"separatrix y = −1", "L–P radius |y| = 1"} <= legend


@pytest.mark.parametrize("kind,axes,field", [
    ("stability", {"omega": [1.0, 1.1, 1.2, 1.3], "force": [0.1, 0.188889, 0.3], "eps": [0.1],
                   "Q": [20.0]}, "stable_orbits"),
])
def test_sweep_figure_counts_on_a_discrete_colourbar(tmp_path, monkeypatch, kind, axes, field):
    """A count's map: a colourbar whose ticks are the whole numbers drawn, a BoundaryNorm
    (one colour each); the cuts' legend rounds the axis values (f = 0.189) with symbols."""
    import xarray as xr
    from matplotlib.colors import BoundaryNorm

    shape = [len(v) for v in axes.values()]
    counts = np.ones(shape, dtype="int8")
    counts[1:, 1:] = 2
    ds = xr.Dataset({field: (list(axes), counts, {"long_name": "distinct Floquet-stable orbits"}),
                     "done": ("block", np.ones(1, dtype=bool))}, coords=axes,
                    attrs={"headline": field, "kind": kind,
                           "sweep": '{"axes": ["omega", "force", "eps", "Q"]}'})
    drawn = _drawn(monkeypatch)
    charts.sweep_figure(ds, tmp_path / "atlas.png")
    (fig,) = drawn
    bar = fig.axes[-1]
    ticks = bar.get_yticks()
    assert list(ticks) == [1, 2] and all(float(t).is_integer() for t in ticks)
    assert isinstance(fig.axes[0].collections[0].norm, BoundaryNorm)
    assert fig.axes[0].get_xlabel() == "drive frequency ω/ω₀"
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert "f = 0.189" in labels
    _digits_ok(_texts(fig))
    assert "ε = 0.1" in fig._suptitle.get_text()


def test_value_rounds_to_three_digits():
    assert [charts._value(v) for v in (0.188889, 20.0, 1 / 3, 1234.5)] == [
        "0.189", "20", "0.333", "1.23e+03"]
    assert charts._named("force", 0.188889) == "f = 0.189"


def test_frequency_energy_plot_puts_the_shot_orbits_on_the_backbones(tmp_path, monkeypatch):
    """Kerschen's system: each mode's series backbone, orbits shot beside it (those inside the
    series' reach lie on it to 1e-9), the reach and the resonance lines in the legend."""
    from lindstedt import charts_modes
    from lindstedt.analysis.curves import frequency_energy
    from lindstedt.derive.system import parse_system

    drawn = []
    monkeypatch.setattr(charts_modes, "_save",
                        lambda fig, path: (drawn.append(fig), charts._save(fig, path))[1])
    system = parse_system("x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0")
    charts_modes.nnm_figure(frequency_energy(system), tmp_path / "fep.png")
    (fig,) = drawn
    (ax,) = fig.axes
    texts = _texts(fig)
    for k in (1, 2):
        assert any(t.startswith(f"mode {k}: series to order") for t in texts)
        assert any(t.startswith(f"mode {k}: orbits shot") for t in texts)
        assert any(t.startswith(f"mode {k}: the series' estimated reach") for t in texts)
    assert any("internal resonance" in t for t in texts)
    lines = {line.get_label(): line for line in ax.lines}
    for k in (1, 2):
        series = lines[next(t for t in lines if t.startswith(f"mode {k}: series"))]
        shots = lines[next(t for t in lines if t.startswith(f"mode {k}: orbits"))]
        E, w = series.get_xdata(), series.get_ydata()
        inside = shots.get_xdata() < E[-1]
        assert inside.sum() >= 4
        on_line = np.interp(np.log(shots.get_xdata()[inside]), np.log(E), w)
        assert np.max(np.abs(on_line / shots.get_ydata()[inside] - 1)) < 1e-4  # interpolated
    assert (tmp_path / "fep.png").stat().st_size > 0
