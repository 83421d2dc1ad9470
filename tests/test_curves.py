"""``--plot`` and ``--csv`` of series, limit cycles and slow flows: the points written are the
series summed exactly (and the truth where it converges), the figure marks the radius and the
orbit edge the JSON states, the same command writes the same bytes, and a bad path is refused
in one line before any work."""

from __future__ import annotations

import csv
import json
import math
from fractions import Fraction

import mpmath
import pytest
from lindstedt import charts_series, cli
from lindstedt.cli.common import check_csv_path
from lindstedt.errors import InputError


def _rows(path):
    with path.open(newline="") as fh:
        table = list(csv.reader(fh))
    return table[0], [[float(x) for x in row] for row in table[1:]]


def _exact(coefficients: list[str], x: float) -> float:
    """``Σ c_j x^j`` in exact rationals at the double ``x``, rounded once."""
    return float(sum(Fraction(c) * Fraction(x) ** j for j, c in enumerate(coefficients)))


def _drawn(monkeypatch):
    drawn = []
    save = charts_series._save
    monkeypatch.setattr(charts_series, "_save",
                        lambda fig, path: (drawn.append(fig), save(fig, path))[1])
    return drawn


def test_series_csv_and_figure_print_the_json(tmp_path, monkeypatch, capsys):
    """Duffing to order 8: every CSV row is the exact series at its y (to a rounding), and
    Duffing's exact ω (the elliptic K) within the truncation for |y| ≤ 0.3; the figure's
    radius lines sit at ±(the JSON's radius), its orbit edge at the JSON's lower edge; a
    second run writes the same bytes."""
    drawn = _drawn(monkeypatch)
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert cli.main(["series", "duffing", "--order", "8", "--json", "--plot", str(a),
                     "--csv", str(tmp_path / "s.csv")]) == 0
    data = json.loads(capsys.readouterr().out)
    header, rows = _rows(tmp_path / "s.csv")
    assert header[:3] == ["y [expansion variable y = eps*A**2]",
                          "omega [frequency in units of omega0]",
                          "period [T/(2*pi) in units of 1/omega0]"]
    radius, lower = float(data["radius"]), float(data["orbit_limit"]["lower"])
    assert rows[0][0] == lower and rows[-1][0] == 1.25 * radius
    for y, omega, period, converges in rows:
        assert omega == pytest.approx(_exact(data["omega"], y), rel=4e-16, abs=4e-16)
        assert period == pytest.approx(_exact(data["period"], y), rel=4e-16, abs=4e-16)
        assert converges == (lower < y and abs(y) < radius)
        if abs(y) <= 0.3:
            m = y / (2 * (1 + y))
            truth = float(mpmath.pi * mpmath.sqrt(1 + y) / (2 * mpmath.ellipk(m)))
            assert abs(omega - truth) < 2e-6
    (fig,) = drawn
    for ax in fig.axes:
        labels = [line.get_label() for line in ax.lines]
        assert "radius of convergence |y| = 1 (exact)" in labels
        assert "orbit edge: no periodic orbit beyond" in labels
        dashed = sorted({x for line in ax.lines if line.get_linestyle() == "--"
                         for x in line.get_xdata()})
        assert dashed == [-radius, radius]  # both within the drawn range
        edges = {x for line in ax.lines if line.get_color() == "0.4" for x in line.get_xdata()}
        assert edges == {lower}  # no edge on the hardening side
    cli.main(["series", "duffing", "--order", "8", "--plot", str(b)])
    assert a.read_bytes() == b.read_bytes()
    assert "the series converges for |y| < 1 (the radius, exact)" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png", "s.csv"]


def test_series_table_states_the_estimated_radius(capsys):
    """Where the model states no radius, the table gives the JSON's estimate."""
    eq = "q'' + q + eps*q**2 = 0"
    cli.main(["series", eq, "--order", "8", "--json"])
    estimate = json.loads(capsys.readouterr().out)["radius_estimate"]["value"]
    cli.main(["series", eq, "--order", "8"])
    assert f"the series converges for |y| < {estimate:.6g} (the radius estimated" in \
        capsys.readouterr().out


def test_limit_cycle_csv_is_van_der_pols_known_series(tmp_path, capsys):
    """Van der Pol's cycle: amplitude 2 + ε²/96 − 1033ε⁴/552960 and ω = 1 − ε²/16 +
    17ε⁴/3072 (Andersen & Geer), summed at each ε of the CSV."""
    path = tmp_path / "c.csv"
    assert cli.main(["series", "van_der_pol", "--order", "4", "--csv", str(path)]) == 0
    assert "radius of convergence in eps not estimated" in capsys.readouterr().out
    header, rows = _rows(path)
    assert [h.split(" [")[0] for h in header] == ["eps", "amplitude", "omega", "period"]
    assert rows[0][0] == 0 and rows[-1][0] == 1
    for eps, amplitude, omega, _ in rows:
        assert amplitude == pytest.approx(_exact(["2", "0", "1/96", "0", "-1033/552960"], eps),
                                          rel=4e-16)
        assert omega == pytest.approx(_exact(["1", "0", "-1/16", "0", "17/3072"], eps),
                                      rel=4e-16)


def test_slow_flow_portrait_follows_the_closed_form(tmp_path, monkeypatch, capsys):
    """Van der Pol's first-order flow dr/dt = ε(r/2 − r³/8) has r² = 4/(1 + (4/r₀² − 1)e^(−εt)):
    every CSV point is on it; the figure draws the attracting cycle r = 2 and the origin."""
    drawn = _drawn(monkeypatch)
    path = tmp_path / "f.csv"
    assert cli.main(["slowflow", "q'' + q = eps*(1 - q**2)*q'", "--order", "1", "--eps",
                     "0.2", "--csv", str(path), "--plot", str(tmp_path / "f.png")]) == 0
    header, rows = _rows(path)
    assert header == ["trajectory [number from 1]", "t [time]", "x [r cos(phi)]",
                      "y [r sin(phi)]"]
    starts = {}
    for k, t, x, y in rows:
        r0 = starts.setdefault(k, math.hypot(x, y))
        truth = 2 / math.sqrt(1 + (4 / r0**2 - 1) * math.exp(-0.2 * t))
        assert math.hypot(x, y) == pytest.approx(truth, rel=1e-7)
    assert len(starts) == 8
    (fig,) = drawn
    labels = [line.get_label() for line in fig.axes[0].lines]
    assert "limit cycle r = 2 (attracting)" in labels
    assert "fixed point (unstable)" in labels


@pytest.mark.parametrize("args", [
    ["series", "duffing"],
    ["slowflow", "q'' + q = eps*(1 - q**2)*q'"],
])
def test_bad_csv_paths_are_refused_in_one_line(tmp_path, capsys, args):
    """A missing folder, a folder, a file lindstedt did not write: exit 2, one line naming
    --csv, nothing written; a CSV it wrote is replaced."""
    foreign = tmp_path / "mine.csv"
    foreign.write_text("a,b\n1,2\n")
    for bad in (tmp_path / "no" / "x.csv", tmp_path, foreign):
        assert cli.main([*args, "--csv", str(bad)]) == 2
        out = capsys.readouterr()
        assert out.out == "" and len(out.err.splitlines()) == 1
        assert "--csv" in out.err or str(bad) in out.err
    assert foreign.read_text() == "a,b\n1,2\n"
    ours = tmp_path / "ours.csv"
    assert cli.main([*args, "--csv", str(ours)]) == 0
    first = ours.read_bytes()
    assert cli.main([*args, "--csv", str(ours)]) == 0
    assert ours.read_bytes() == first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.csv", "ours.csv"]


def test_check_csv_path_names_the_flag():
    with pytest.raises(InputError, match="--csv"):
        check_csv_path("")


def test_system_exchange_csv_keeps_the_manley_rowe_invariant(tmp_path, monkeypatch, capsys):
    """``x1'' + x1 + x1 x2 = 0; x2'' + 4 x2 + x1²/2 = 0`` (1:2): its flow a1' = a1 a2 sinγ/4,
    a2' = −a1² sinγ/16 keeps a1² + 4 a2² (by hand: d(a1²)/dt = a1² a2 sinγ/2 = −4 d(a2²)/dt);
    every CSV row holds it, the CSV's maxima of a1 lie one printed period apart, and the
    figure draws both amplitudes."""
    from lindstedt import charts_modes

    drawn = []
    save = charts_modes._save
    monkeypatch.setattr(charts_modes, "_save",
                        lambda fig, path: (drawn.append(fig), save(fig, path))[1])
    path = tmp_path / "x.csv"
    system = "x1'' + x1 + x1*x2 = 0; x2'' + 4*x2 + x1**2/2 = 0"
    assert cli.main(["slowflow", system, "--start", "a1=0.05", "--json", "--csv", str(path),
                     "--plot", str(tmp_path / "x.png")]) == 0
    period = json.loads(capsys.readouterr().out)["exchange"]["period"]
    header, rows = _rows(path)
    assert header == ["t [time]", "a1 [amplitude of resonant mode 1]",
                      "a2 [amplitude of resonant mode 2]"]
    assert rows[0] == [0.0, 0.05, 0.1]
    invariant = 0.05**2 + 4 * 0.1**2
    for _, a1, a2 in rows:
        assert a1**2 + 4 * a2**2 == pytest.approx(invariant, rel=1e-8)
    peaks = [rows[k][0] for k in range(1, len(rows) - 1)
             if rows[k - 1][1] < rows[k][1] >= rows[k + 1][1]]
    assert len(peaks) >= 2
    spacing = rows[1][0] - rows[0][0]
    assert abs(peaks[1] - peaks[0] - period) <= 2 * spacing
    (fig,) = drawn
    assert [line.get_label()[:3] for line in fig.axes[0].lines][:2] == ["a1:", "a2:"]


def test_response_csv_of_a_linear_oscillator_is_its_closed_form(tmp_path, capsys):
    """``x'' + c x' + x = f cos(ωt)``: r = f / sqrt((1 − ω²)² + (cω)²) at every CSV row."""
    path = tmp_path / "r.csv"
    assert cli.main(["response", "x'' + 0.1*x' + x = 0.3*cos(w*t)", "--omega", "0.5:1.5",
                     "--csv", str(path)]) == 0
    capsys.readouterr()
    header, rows = _rows(path)
    assert header[:3] == ["branch [piece of the continued balance from 1]",
                          "omega [drive frequency]", "r [first harmonic sqrt(A1^2 + B1^2)]"]
    assert {row[0] for row in rows} == {1.0} and len(rows) > 50
    assert min(row[1] for row in rows) <= 0.5 and max(row[1] for row in rows) >= 1.5  # range
    for _, w, r, *_ in rows:
        assert r == pytest.approx(0.3 / math.hypot(1 - w * w, 0.1 * w), rel=1e-10)


def test_slowflow_portrait_flags_are_refused_where_they_mean_nothing(capsys):
    for args in (["slowflow", "q'' + q = eps*(1 - q**2)*q'", "--eps", "0.1"],
                 ["slowflow", "x1'' + x1 = 0; x2'' + 4*x2 + x1**2 = 0", "--eps", "0.1",
                  "--plot", "p.png"]):
        assert cli.main(args) == 2
        assert len(capsys.readouterr().err.splitlines()) == 1
