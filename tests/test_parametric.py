"""The parametrically driven oscillator q'' + 2ζq' + (1 + ε cos 2ωt)q + γq³ = 0 and the full Hill
equation: one harmonic against an FFT projection, Mathieu's characteristic values (SciPy) and
shooting; stability verdicts against the Floquet multipliers of shot orbits."""

from __future__ import annotations

import json
import math
import subprocess

import commands
import numpy as np
import pytest
from lindstedt.analysis.driven import Drive, amplitudes
from lindstedt.analysis.parametric import (
    Pump,
    balance_point,
    fold,
    one_harmonic,
    onsets,
    parametric_secular,
    shoot_orbit,
    tongue_edges,
    trivial_orbit,
)
from lindstedt.analysis.periodic import periodic_orbits
from lindstedt.analysis.subharmonic import subharmonic
from lindstedt.numerics.floquet import multipliers_stable, orbit_hill_multipliers
from scipy.optimize import brentq
from scipy.special import mathieu_a, mathieu_b


def fft_secular(p: Pump, omega: float, a: float, b: float) -> np.ndarray:
    """(cos, sin) coefficients of the equation's left side on q = a cos θ + b sin θ, by sampling
    a period and an FFT: an independent route to the one-harmonic balance."""
    theta = 2 * np.pi * np.arange(64) / 64
    q = a * np.cos(theta) + b * np.sin(theta)
    v = omega * (-a * np.sin(theta) + b * np.cos(theta))
    lhs = -omega**2 * q + 2 * p.zeta * v + (1 + p.eps * np.cos(2 * theta)) * q + p.gamma * q**3
    c = np.fft.rfft(lhs) / 64
    return np.array([2 * c[1].real, -2 * c[1].imag])


def fd_jacobian(p: Pump, omega: float, a: float, b: float) -> np.ndarray:
    h = 1e-6
    cols = [(fft_secular(p, omega, a + h * e[0], b + h * e[1])
             - fft_secular(p, omega, a - h * e[0], b - h * e[1])) / (2 * h)
            for e in ((1, 0), (0, 1))]
    return np.column_stack(cols)


def test_secular_conditions_match_the_fft_projection():
    import sympy as sp

    cos_eq, sin_eq = parametric_secular()
    syms = sp.symbols("a b omega epsilon zeta gamma")
    vals = (0.3, -0.7, 1.1, 0.25, 0.03, -1.5)
    p = Pump(vals[3], vals[4], vals[5])
    got = [float(e.subs(dict(zip(syms, vals, strict=True)))) for e in (cos_eq, sin_eq)]
    np.testing.assert_allclose(got, fft_secular(p, vals[2], vals[0], vals[1]), atol=1e-14)


@pytest.mark.parametrize("gamma", [1.0, -0.5])
@pytest.mark.parametrize("omega", [0.93, 0.97, 1.0, 1.04, 1.08])
def test_one_harmonic_branches_balance_and_their_slow_flow_verdict(gamma, omega):
    """Each nontrivial point zeroes the FFT balance; its verdict is the slow flow's: the
    Jacobian of (ȧ, ḃ) = (P_s, −P_c)/(2ω) by finite differences has both eigenvalues in the
    left half plane exactly when the point is called stable."""
    p = Pump(0.2, 0.01, gamma)
    points = one_harmonic(p, omega)
    assert points[0].branch == "0"
    for pt in points[1:]:
        np.testing.assert_allclose(fft_secular(p, omega, pt.a, pt.b), 0, atol=1e-13)
        J = fd_jacobian(p, omega, pt.a, pt.b)
        slow = np.array([J[1], -J[0]]) / (2 * omega)
        assert pt.stable == bool(np.all(np.linalg.eigvals(slow).real < 0)), pt


def true_edges(eps: float) -> tuple[float, float]:
    """The undamped first tongue's edges from Mathieu's a₁, b₁ (SciPy): in τ = ωt the equation
    is q'' + (a − 2q cos 2τ)q = 0 with a = 1/ω², q = −ε/(2ω²)."""
    def edge(char):
        return brentq(lambda w: 1 / w**2 - char(1, eps / (2 * w**2)), 0.5, 1.5)
    return edge(mathieu_a), edge(mathieu_b)


def test_undamped_tongue_edges_against_mathieu():
    """ω² = 1 ± ε/2 at one harmonic; the true edges are ``1 ± ε/2 + ε²/32 ∓ 9ε³/512 + O(ε⁴)``
    (``a₁, b₁ = 1 ± q − q²/8 ∓ q³/64`` at ``q = ε/(2ω²)``, solved for ω² by iteration)."""
    for eps in (0.05, 0.1, 0.2, 0.4):
        lo, hi = tongue_edges(Pump(eps, 0.0, 1.0))
        np.testing.assert_allclose([lo**2, hi**2], [1 - eps / 2, 1 + eps / 2], rtol=1e-14)
        tlo, thi = true_edges(eps)
        for one, true, sign in ((lo, tlo, 1), (hi, thi, -1)):
            assert abs(true**2 - one**2 - eps**2 / 32 - sign * 9 * eps**3 / 512) < 0.02 * eps**4


@pytest.mark.parametrize("eps", [0.05, 0.1, 0.2])
def test_damped_onset_against_floquet_of_the_zero_state(eps):
    """The one-harmonic edges are where q = 0 loses stability (damped Mathieu, Floquet
    multipliers of the linear equation by RK4) within O(ε²)."""
    p = Pump(eps, eps / 10, 1.0)
    lo, hi = tongue_edges(p)

    def unstable(w):
        return not trivial_orbit(p, w).stable

    for edge, inside in ((lo, 1), (hi, -1)):
        true = brentq(lambda w: abs(max(abs(trivial_orbit(p, w).multipliers))) - 1,
                      edge - inside * 0.3 * eps, edge + inside * 0.3 * eps, xtol=1e-12)
        assert abs(true - edge) < 0.1 * eps**2
        assert unstable(true + inside * 0.01 * eps) and not unstable(true - inside * 0.01 * eps)


def test_branches_against_shooting_error_shrinks_with_eps():
    """The one-harmonic amplitude against the shot orbit's first harmonic: the relative error
    falls with ε (amplitudes r² ∝ ε on a fixed ω² − 1 ∝ ε); the balance is within 1e-9."""
    errors = []
    for eps in (0.05, 0.1, 0.2):
        p = Pump(eps, eps / 20, 1.0)
        worst = 0.0
        for w2 in (1.0, 1 + 0.25 * eps, 1 + 0.75 * eps):
            for pt in one_harmonic(p, math.sqrt(w2))[1:]:
                bal = balance_point(p, pt)
                orbit = shoot_orbit(p, pt.omega, bal.A, bal.B)
                r = math.hypot(orbit.A[1], orbit.B[1])
                assert abs(bal.r - r) < 1e-9 * r
                worst = max(worst, abs(pt.r - r) / r)
        errors.append(worst)
    assert errors[0] < errors[1] < errors[2] < 0.05
    assert errors[2] / errors[0] > 2


@pytest.mark.parametrize("zeta", [0.01, 0.0])
@pytest.mark.parametrize("gamma", [1.0, -1.0])
def test_verdicts_against_floquet_multipliers_of_shot_orbits(gamma, zeta):
    """One harmonic, full Hill about the balance and shooting agree on every branch (undamped:
    the slow flow's centre is the orbit's pair on the unit circle); the full Hill multipliers
    are the shot orbit's."""
    p = Pump(0.2, zeta, gamma)
    seen = set()
    for w in (0.93, 0.96, 1.0, 1.04, 1.07):
        for pt in one_harmonic(p, w)[1:]:
            bal = balance_point(p, pt)
            orbit = shoot_orbit(p, w, bal.A, bal.B)
            assert pt.stable == bal.stable == orbit.stable, (w, pt)
            np.testing.assert_allclose(np.sort_complex(bal.multipliers),
                                       np.sort_complex(orbit.multipliers), atol=1e-8)
            seen.add((pt.branch, pt.stable))
    assert len(seen) == 2  # a stable and an unstable branch were both checked


@pytest.mark.parametrize("gamma", [1.0, -1.0])
def test_onsets_super_and_subcritical_by_shooting(gamma):
    """The supercritical branch is the stable one entering the tongue, the subcritical one
    the unstable one outside it: checked on shot orbits near each onset."""
    p = Pump(0.2, 0.01, gamma)
    lo, hi = tongue_edges(p)
    first, second = onsets(p)
    assert (first.value, second.value) == (lo, hi)
    for o in (first, second):
        inside = lo < o.value + 0.01 < hi
        w = o.value + (0.01 if o.supercritical == inside else -0.01)
        pt = next(x for x in one_harmonic(p, w) if x.branch == o.branch)
        orbit = shoot_orbit(p, w, {1: pt.a}, {1: pt.b})
        assert orbit.stable == o.supercritical
        assert (lo < w < hi) == o.supercritical


def test_fold_where_the_branches_meet():
    """At s = 0 the balance Jacobian (FFT, finite differences) is singular (its determinant
    3γκr² of the module docstring); just below it both branches exist, close together; above,
    none."""
    p = Pump(0.2, 0.04, 1.0)
    w, r = fold(p)
    assert w == pytest.approx(1.25) and r == pytest.approx(math.sqrt(0.75))
    below = one_harmonic(p, w * (1 - 1e-8))
    assert [x.branch for x in below] == ["0", "+", "-"]
    assert abs(below[1].r - below[2].r) < 1e-3
    for pt, kappa in ((below[1], 1), (below[2], -1)):  # det ∂P/∂(a, b) = 3γκr², κ = ±s → 0
        s = math.sqrt(p.eps**2 / 4 - 4 * p.zeta**2 * pt.omega**2)
        det = np.linalg.det(fd_jacobian(p, pt.omega, pt.a, pt.b))
        assert det == pytest.approx(3 * p.gamma * kappa * s * pt.r**2, rel=1e-3)
        assert abs(det) < 1e-4
    assert [x.branch for x in one_harmonic(p, w * (1 + 1e-8))] == ["0"]
    assert fold(Pump(0.2, 0.0, 1.0)) is None and fold(Pump(0.2, 0.04, -1.0)) is None


def test_full_hill_corrects_the_notes_verdict_on_the_subharmonic():
    """ε = 0.1, f = 0.5, ω = 1.3: q₀'s Hill equation calls the '−' root stable; the full Hill
    equation about the balance orbit and shooting call it unstable, with the same
    multipliers."""
    _, _, sols = subharmonic(0.1, 0.5, 1.3)
    by = {s.root: s for s in sols}
    assert by["-"].hill_stable and not by["-"].orbit.stable
    for s in sols:
        assert s.full_hill_stable == s.orbit.stable
        np.testing.assert_allclose(np.sort_complex(s.full_hill_multipliers),
                                   np.sort_complex(s.orbit.multipliers), atol=1e-9)


def test_full_hill_near_the_subharmonic_fold():
    """ε = 0.1, ω = 1.05, f = 7.8 (the roots meet at f = 7.885): both orbits within 3e-3 of
    |tr M| = 2, the full Hill verdicts still shooting's; past the true fold no verdict."""
    _, _, sols = subharmonic(0.1, 7.8, 1.05)
    for s in sols:
        assert abs(abs(np.sum(s.orbit.multipliers).real) - 2) < 3e-3
        assert s.full_hill_stable == s.orbit.stable == (s.root == "+")
    _, _, sols = subharmonic(0.1, 7.88, 1.05)
    assert all(s.full_hill_stable is None and s.orbit is None for s in sols)


@pytest.mark.parametrize("eps,force,Q,omega", [(0.1, 1.0, 20.0, 1.4), (0.1, 0.3, 20.0, 1.3),
                                                (-0.05, 0.2, 30.0, 0.9), (0.1, 1.0, 20.0, 0.8)])
def test_full_hill_on_driven_duffing_branches(eps, force, Q, omega):
    """Driven Duffing: the full Hill equation about each harmonic-balance orbit has the shot
    orbit's Floquet multipliers and verdict; cut to the balance's first harmonic (the notes'
    q₀) it does not have them."""
    d = Drive(eps, force, omega, Q)
    terms = {(1, 0): 1.0, (3, 0): eps, (0, 1): d.damping}
    found = periodic_orbits(d, harmonics=8)
    cut_errors = []
    for orb in found.orbits:
        if orb.orbit is None or orb.balance is None:
            continue
        A, B = amplitudes(orb.balance.coefficients, 0.0, 15)
        lam = orbit_hill_multipliers(terms, A, B, omega)
        true = np.sort_complex(orb.orbit.multipliers)
        np.testing.assert_allclose(np.sort_complex(lam), true, atol=1e-8)
        assert multipliers_stable(lam, True) == orb.orbit.stable
        cut = orbit_hill_multipliers(terms, {1: A[1]}, {1: B[1]}, omega)
        cut_errors.append(float(np.max(np.abs(np.sort_complex(cut) - true))))
    assert len(cut_errors) == len(found.orbits) >= 1
    assert max(cut_errors) > 1e-4, cut_errors  # the higher harmonics matter somewhere


def run(*args: str) -> subprocess.CompletedProcess:
    return commands.run(*args)


def test_parametric_command_contract_and_bad_input():
    out = run("parametric", "--eps", "0.2", "--zeta", "0.01", "--omega", "0.95:1.1:4", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["onsets"][0]["supercritical"] and not data["onsets"][1]["supercritical"]
    shot = [b for b in data["branches"] if b["shooting"] and b["branch"] != "0"]
    assert shot and all(b["shooting"]["stable"] == b["balance"]["full_hill_stable"]
                        == b["one_harmonic"]["stable"] for b in shot)
    for bad, needle in ((["--eps", "0.2", "--zeta", "-1"], "zeta"),
                        (["--eps", "0", "--zeta", "0"], "eps"),
                        (["--eps", "0.2", "--gamma", "inf"], "gamma")):
        out = run("parametric", *bad, "--omega", "0.9:1.1")
        assert out.returncode == 2 and needle in out.stderr
        assert len(out.stderr.strip().splitlines()) == 1
    out = run("parametric", "--eps", "0.2", "--omega", "1.1:0.9")
    assert out.returncode == 2 and "--omega 1.1:0.9: the range must increase" in out.stderr


def test_subharmonic_json_gains_the_full_hill_verdict():
    out = run("subharmonic", "--eps", "0.1", "--force", "0.5", "--omega", "1.3", "--json")
    assert out.returncode == 0, out.stderr
    sols = {s["root"]: s for s in json.loads(out.stdout)["solutions"]}
    assert sols["-"]["hill_stable"] and not sols["-"]["full_hill"]["stable"]
    assert sols["-"]["numerical"]["stable"] is False and sols["+"]["full_hill"]["stable"]


def test_parametric_figure_is_drawn_and_a_bad_input_draws_nothing(tmp_path, capsys):
    from lindstedt import cli

    path = tmp_path / "p.png"
    args = ["parametric", "--eps", "0.2", "--zeta", "0.01", "--omega", "0.9:1.1:2"]
    assert cli.main([*args, "--zeta", "2", "--plot", str(path)]) == 2
    assert list(tmp_path.iterdir()) == []
    assert cli.main([*args, "--plot", str(path)]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()


@pytest.mark.parametrize(("eps", "zeta", "outside"), [(0.1, 0.01, True), (0.1, 0.0235, False)])
def test_a_fold_outside_the_range_or_the_model_says_so(eps, zeta, outside):
    """The one-harmonic fold ω = ε/(4ζ) is flagged where printed: outside the range, and
    outside the model where ¾γr² > 1 — there the balance continued through its true fold (6
    harmonics, shooting's equal to 1e-12 here) puts it > 5 % away, inside the model < 2 %."""
    from lindstedt.analysis.continuation import _continue
    from lindstedt.analysis.parametric import ParametricBalance, parametric_report
    from lindstedt.cli.driven import _parametric_table, parametric_report_json

    p = Pump(eps, zeta, 1.0)
    w1, r1 = fold(p)
    assert w1 == pytest.approx(eps / (4 * zeta), rel=1e-15)
    data = parametric_report_json(parametric_report(eps, zeta, 1.0, 0.9, 1.0, points=2,
                                                    harmonics=3))
    f = data["fold"]
    assert not f["in_range"] and f["in_model"] == (not outside)
    assert (0.75 * r1 * r1 > 1) == outside
    line = next(x for x in _parametric_table(data) if x.startswith("fold"))
    assert "outside the range [0.9, 1]" in line
    assert ("outside the one-harmonic model" in line) == outside
    # the true fold: the balance traced in ω from the + branch halfway to the formula's fold
    w0 = 0.5 * (1 + w1)
    start = next(q for q in one_harmonic(p, w0) if q.branch == "+")
    balance = ParametricBalance(p, 6)
    x = np.zeros(balance.size)
    x[0], x[6] = start.a, start.b
    x, converged, _ = balance.solve(x, w0)
    assert converged
    curve = _continue(balance, lambda: ([(w0, x, 1.0)], True), w0, 1.5 * w1, 0.02, 1000, 60,
                      5e-3, 20000, "the pumped oscillator")
    true = min(curve.folds, key=lambda w: abs(w - w1))
    assert (abs(true / w1 - 1) > 0.05) == outside and abs(true / w1 - 1) < 0.1, true
