"""Figures: written atomically, byte-reproducible, bad paths refused before any work."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from lindstedt import charts, cli
from lindstedt.charts import check_plot_path, mixing_figure
from lindstedt.cli import driven as cli_driven
from lindstedt.errors import InputError
from lindstedt.numerics.integrate import duffing_table
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
    mixing_figure(duffing_table(MIX_EPS, 1 / MIX_Q), MIX_DRIVES, a, "eps = 0.1")
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
    mixing_figure(duffing_table(MIX_EPS, 1 / MIX_Q), MIX_DRIVES, b, "eps = 0.1")
    assert a.read_bytes() == b.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]  # no temporaries


@pytest.mark.parametrize("bad", ["out.jpg", "/no/such/folder/x.png", "noext"])
def test_bad_plot_paths(bad):
    with pytest.raises(InputError):
        check_plot_path(bad)


class Computed(Exception):
    """Raised by the stand-in for a command's computation."""


@pytest.mark.parametrize("args,compute", [
    (["response", "--eps", "0.1", "--force", "0.3", "--Q", "20"], "response_json"),
    (["subharmonic", "--eps", "0.1", "--force", "0.5", "--omega", "1.2"], "subharmonic_json"),
    (["mixing", "--eps", "0.1", "--Q", "10", "--drive", "0.3@1.3"], "mixing_json"),
])
def test_cli_refuses_bad_plot_path_before_computing(tmp_path, monkeypatch, capsys, args,
                                                    compute):
    """The computation is replaced by a stand-in that records its call and raises: with a
    good --plot the command reaches it, with a bad one it answers 2 without calling it."""
    calls = []

    def stand_in(*a, **kw):
        calls.append(a)
        raise Computed

    monkeypatch.setattr(cli_driven, compute, stand_in)
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
    from lindstedt.analysis.subharmonic import subharmonic

    drawn = []
    save = charts._save
    monkeypatch.setattr(charts, "_save", lambda fig, path: (drawn.append(fig), save(fig, path))[1])
    charts.subharmonic_figure(0.1, 0.5, tmp_path / "s.png")
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
