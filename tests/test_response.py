"""Response curves: folds of the cubic, continuation, true folds, sweep jumps (§10.4)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from commands import run_forked
from lindstedt.analysis.driven import Drive, amplitude_residual, amplitude_slope
from lindstedt.analysis.response import OneHarmonic, first_harmonic, one_harmonic_curve
from lindstedt.analysis.systems import continue_balance
from lindstedt.numerics.integrate import duffing_table, sweep
from lindstedt.numerics.shooting import orbit_fold, shoot

EPS, F, Q = 0.1, 0.3, 20.0
REFERENCE_FOLDS = {
    (0.1, 0.3, 20.0): (1.1618653039085556, 1.4893933393651175),
    (-0.1, 0.3, 20.0): (0.8039032157810019,),
    (0.1, 0.3, 185.0): (1.164938605148117, 3.963272238735694),
    (1.0, 0.05, 185.0): (1.1103722095597486, 2.9199877180685214),
    (0.01, 0.05, 1e4): (1.0247962306602898, 6.618470884248357),
    (2.0, 30.0, 3.0): (4.669026606847833, 10.523414823985),
    (0.1, 1.0, math.inf): (1.340520021069047,),
    (-0.1, -1.0, math.inf): (0.4505619525803768,),
}
# NOTE: eq. 10.60's one-harmonic folds from the cubic's discriminant in closed form (SymPy's
# resultant in u = r², its roots in ω² polished by Newton on the cubic written factored, as
# lindstedt 0.x computed them for eq. 10.60 alone), to the last printed digit.


def one_harmonic_folds(eps, force, Q):
    """The folds of eq. 10.60's one-harmonic balance (the one fold finder for any force)."""
    return OneHarmonic(Drive(eps, force, 1.0, Q).terms, force).folds


def discriminant_folds(eps, force, Q, lo, hi, points=200_001):
    """Independent: where the discriminant of the cubic ``a u³ + b u² + c u + d`` in ``u = r²``
    (``18abcd − 4b³d + b²c² − 4ac³ − 27a²d²``) changes sign on a fine ω grid with a positive
    double root, refined by bisection (brentq)."""
    from scipy.optimize import brentq

    def disc(w):
        s = 1 - w * w
        a, b, c, d = 9 / 16 * eps**2, 1.5 * eps * s, s * s + w * w / Q**2, -force**2
        return 18 * a * b * c * d - 4 * b**3 * d + b * b * c * c - 4 * a * c**3 \
            - 27 * a * a * d * d

    grid = np.linspace(lo, hi, points)
    values = disc(grid)
    return [brentq(disc, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15)
            for i in np.nonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]]


def cubic_roots(omega):
    """Positive roots u = r² by numpy.roots: an independent solver."""
    a = 1 - omega**2
    u = np.roots([9 / 16 * EPS**2, 1.5 * EPS * a, a * a + omega**2 / Q**2, -F**2])
    return sorted((x.real for x in u if abs(x.imag) < 1e-9 and x.real > 0), reverse=True)


def test_curve_equals_numpy_roots_and_stability():
    omega = np.linspace(0.6, 1.8, 301)
    curve = one_harmonic_curve(EPS, F, Q, omega)
    for i, w in enumerate(omega):
        ref = np.sqrt(cubic_roots(w))
        got = curve.r[i][np.isfinite(curve.r[i])]
        np.testing.assert_allclose(got, ref, rtol=1e-10)
    i = int(np.argmin(np.abs(omega - 1.3)))  # inside the loop: three branches
    assert list(curve.stable[i]) == [True, False, True]


def test_any_forces_curve_is_the_cubics_closed_form():
    """:meth:`OneHarmonic.curve` (the roots of any force's H(r), ∂G/∂u > 0 as the verdict)
    equals eq. 10.60's vectorised closed form (:func:`one_harmonic_curve`), branch by
    branch."""
    omega = np.linspace(0.6, 1.8, 301)
    closed = one_harmonic_curve(EPS, F, Q, omega)
    general = OneHarmonic(Drive(EPS, F, 1.0, Q).terms, F).curve(omega)
    width = general.r.shape[1]
    assert width == 3
    np.testing.assert_allclose(general.r, closed.r[:, :width], rtol=1e-10)
    assert (general.stable == closed.stable[:, :width]).all()


def test_folds_are_double_roots_and_change_the_branch_count():
    folds = one_harmonic_folds(EPS, F, Q)
    assert len(folds) == 2
    assert folds == REFERENCE_FOLDS[EPS, F, Q]  # to the last bit
    d = Drive(EPS, F, 1.0, Q)
    for w in folds:
        assert len(cubic_roots(w - 1e-7)) + len(cubic_roots(w + 1e-7)) == 4  # 1 | 3
        # a double root u: G(u) = ∂G/∂u = 0 to rounding
        u = np.roots([27 / 16 * EPS**2, 3 * EPS * (1 - w**2), (1 - w**2) ** 2 + w**2 / Q**2])
        u = min((x.real for x in u if abs(x.imag) < 1e-6 and x.real > 0),
                key=lambda x: abs(amplitude_residual(x, w, d)))
        assert abs(amplitude_residual(u, w, d)) < 1e-12
        assert abs(amplitude_slope(u, w, d)) < 1e-12


@pytest.mark.parametrize("params", sorted(REFERENCE_FOLDS, key=str))
def test_the_one_fold_finder_reproduces_the_cubics_folds(params):
    """The resultant of any polynomial force's G(u, w) and ∂G/∂u, polished by Newton: eq.
    10.60's folds as the cubic's closed form gave them, within two units in the last place."""
    got = one_harmonic_folds(*params)
    assert len(got) == len(REFERENCE_FOLDS[params])
    np.testing.assert_allclose(got, REFERENCE_FOLDS[params], rtol=5e-16, atol=0)


@pytest.mark.parametrize("force, apart, rtol", [(0.057, 6.5e-4, 1e-14), (0.0541, 1.3e-6, 1e-11)])
def test_folds_closer_than_a_grid_step_are_told_apart(force, apart, rtol):
    """Just above the cusp (f ≈ 0.05406 at ε = 0.1, Q = 20, where hysteresis begins) the two
    folds lie 0.065 % and 1.3e-6 of ω apart, within one step of a 0.3 % grid (which found
    neither): both found, each where the discriminant of the cubic changes sign (brentq on a
    5e-7 grid, independent; near the cusp the discriminant's own rounding limits it)."""
    eps, Q = 0.1, 20.0
    got = one_harmonic_folds(eps, force, Q)
    assert len(got) == 2 and got[1] / got[0] - 1 == pytest.approx(apart, rel=0.05)
    ref = discriminant_folds(eps, force, Q, 1.0, 1.1)
    assert len(ref) == 2
    np.testing.assert_allclose(got, ref, rtol=rtol)


def test_first_harmonic_coefficients_are_the_quadratures():
    """``C_ab``, ``S_ab`` exact against the 64-point quadrature of cos^a θ (−sin θ)^b."""
    theta = 2 * np.pi * np.arange(64) / 64
    for a in range(9):
        for b in range(9):
            wave = np.cos(theta) ** a * (-np.sin(theta)) ** b
            cos, sin = first_harmonic(a, b)
            assert abs(2 * np.mean(wave * np.cos(theta)) - float(cos)) < 1e-13
            assert abs(2 * np.mean(wave * np.sin(theta)) - float(sin)) < 1e-13


def test_a_quintic_force_folds_where_its_amplitude_polynomial_is_double():
    """q'' + q'/20 + q + q³/10 − q⁵/100 (hardening then softening): at each fold the
    one-harmonic amplitude polynomial H(r) of numpy has a double positive root (a root of
    H and H')."""
    terms = {(1, 0): 1.0, (0, 1): 0.05, (3, 0): 0.1, (5, 0): -0.01}
    one = OneHarmonic(terms, 0.2)
    assert len(one.folds) >= 2
    for w in one.folds:
        H = one.polynomial(w)
        near = [r for r in np.polynomial.polynomial.polyroots(np.polynomial.polynomial.polyder(H))
                if abs(r.imag) < 1e-6 and r.real > 0]
        assert min(abs(np.polynomial.polynomial.polyval(r.real, H)) for r in near) < 1e-9


def test_balance_folds_are_true_folds_with_floquet_multiplier_one():
    cont = continue_balance(Drive(EPS, F, 0.6, Q).equation, 8, 0.6, 1.9)
    assert len(cont.folds) == 2
    for w in cont.folds:
        x = cont.x[int(np.argmin(np.abs(cont.omega - w)))]
        odd = np.arange(1, 16, 2)
        found = orbit_fold(EPS, F, 1 / Q, w, np.array([x[:8].sum(), w * np.sum(odd * x[8:])]))
        assert found is not None
        assert abs(found[0] - w) < 1e-9  # harmonic balance (N = 8) against the true orbit
    # the Floquet multiplier passes +1 across the upper fold: the middle branch has one > 1
    lo, hi = cont.folds
    w_in = 0.5 * (lo + hi)
    crossings = np.nonzero(np.diff(np.sign(cont.omega - w_in)))[0]
    assert len(crossings) == 3  # upper, middle and lower branch
    moduli = []
    for i in crossings:
        x = cont.x[i]
        y0 = np.array([x[:8].sum(), w_in * np.sum(odd * x[8:])])
        orbit = shoot(EPS, F, w_in, 1 / Q, y0)
        moduli.append(max(abs(orbit.multipliers)))
    assert sorted(m > 1 for m in moduli) == [False, False, True]


def test_sweep_jumps_near_the_folds():
    """Up the sweep falls off the upper branch past the upper fold, down it climbs onto it past
    the lower fold: each jump just beyond that fold, the amplitude on either side on the branch
    the cubic (numpy.roots) says it is on."""
    lo, hi = one_harmonic_folds(EPS, F, Q)
    cont = continue_balance(Drive(EPS, F, 0.6, Q).equation, 8, 0.6, 1.9)
    up = sweep(EPS, F, 1 / Q, 0.6, 1.9)
    down = sweep(EPS, F, 1 / Q, 1.9, 0.6)
    resolution = 0.01  # Δω of the jump window at 10⁴ periods, and the slow-passage lag
    assert abs(up.jump - cont.folds[1]) < resolution
    assert abs(down.jump - cont.folds[0]) < resolution
    # past the fold, never before it: the slow passage lags (by 4.9e-3 up, 2.6e-3 down here)
    assert up.jump > cont.folds[1] and down.jump < cont.folds[0]
    # the one-harmonic folds are 4e-3 off the true ones here (O(ε)): within twice the window
    assert abs(up.jump - hi) < 2 * resolution and abs(down.jump - lo) < 2 * resolution
    for run, before, after in ((up, max, min), (down, min, max)):
        i = int(np.argmin(np.abs(run.omega - run.jump)))
        # 100 samples (Δω ≈ 0.011) before the jump, 150 (Δω ≈ 0.016) after it; max |q| per
        # period: the third harmonic and the lag put it within 1.5 % of r here
        for k, pick in ((i - 100, before), (i + 150, after)):
            r = np.sqrt(pick(cubic_roots(run.omega[k])))
            assert abs(run.amplitude[k] / r - 1) < 0.05, (run.omega[k], run.amplitude[k], r)
    assert sweep(EPS, 0.05, 1 / Q, 0.6, 1.9).jump is None  # no hysteresis, no jump


def test_response_contract_and_bad_input():
    out = run_forked("response", "--eps", "0.1", "--force", "0.3", "--Q", "20", "--harmonics", "4",
                     "--json", check=False)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["one_harmonic"]["folds"] == sorted(data["one_harmonic"]["folds"])
    assert data["harmonic_balance"]["harmonics"] == 4
    assert len(data["numerical"]["folds"]) == 2
    assert {"sweep_up_jump", "sweep_down_jump"} <= data["numerical"].keys()
    for bad in (["--Q", "inf"], ["--Q", "0"], ["--Q", "nan"]):
        run = run_forked("response", "--eps", "0.1", "--force", "0.3", *bad, check=False)
        assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1


def test_the_presets_name_takes_the_notes_flags(capsys):
    """``response duffing --eps --force --Q`` is ``response --eps --force --Q`` (the preset
    of the same problem), its JSON the same to the last bit; without a flag both say which is
    missing, in one line."""
    from lindstedt.cli import main

    flags = ["--eps", "0.1", "--force", "0.3", "--Q", "20", "--harmonics", "4", "--omega",
             "0.8:1.6", "--json"]
    assert main(["response", "duffing", *flags]) == 0
    named = json.loads(capsys.readouterr().out)
    assert main(["response", *flags]) == 0
    assert json.loads(capsys.readouterr().out) == named
    assert named["parameters"]["omega_range"] == [0.8, 1.6] and named["coordinates"] == ["q"]
    for argv in (["response", "duffing", "--eps", "0.1"], ["response", "--eps", "0.1"]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "--force, --Q" in err, err


def test_one_equations_json_holds_both_shapes():
    """One equation's record prints the keys of a system's response too (each branch's
    points with their Floquet verdict, the folds, the search), beside its own: the branch
    points are the continued balance's, the folds the same."""
    from lindstedt.analysis.systems import notes_problem, response
    from lindstedt.cli.response import response_json

    de, closed = notes_problem(EPS, F, Q)
    data = response_json(response(de, 4, 0.8, 1.6, closed=closed))
    assert {"kind", "system", "coordinates", "branches", "folds", "completeness",
            "equation", "one_harmonic", "harmonic_balance", "numerical"} <= data.keys()
    assert data["folds"] == data["harmonic_balance"]["folds"]
    (branch,) = data["branches"]
    r = np.array(branch["amplitudes"]["q"])
    w = np.array(branch["omega"])
    # a one-harmonic root lies within O(ε) of each balance point away from the folds
    i = int(np.argmin(np.abs(w - 0.9)))
    assert abs(r[i] / np.sqrt(cubic_roots(w[i])[0]) - 1) < 0.02
    assert branch["stable"][i] and branch["multiplier"][i] < 1
    assert {"bound", "how"} <= data["completeness"].keys()


@pytest.mark.parametrize("omega", [np.array([0.0]), np.array([np.nan])])
def test_curve_bad_frequency(omega):
    from lindstedt.errors import InputError

    with pytest.raises(InputError):
        one_harmonic_curve(EPS, F, Q, omega)


# --- the 1/3 subharmonic ----------------------------------------------------------------------

def test_subharmonic_secular_conditions_are_the_notes():
    import sympy as sp
    from lindstedt.analysis.subharmonic import subharmonic_secular

    a, b, F, w, e = sp.symbols("a b F omega epsilon")
    cos_eq, sin_eq = subharmonic_secular()
    bracket = (1 - w**2) / e + 3 * F**2 / 2 + sp.Rational(3, 4) * (a**2 + b**2)
    assert sp.expand(cos_eq - (a * bracket - 3 * F / 4 * (b**2 - a**2))) == 0  # eq. 10.85
    assert sp.expand(sin_eq - (b * bracket - 3 * F / 4 * 2 * a * b)) == 0  # eq. 10.86
    # b·(10.85) − a·(10.86) ∝ b(b² − 3a²): solutions b = 0 and a = ±b/√3
    assert sp.factor(b * cos_eq - a * sin_eq) == sp.factor(-3 * F / 4 * b * (b**2 - 3 * a**2))
    # eq. 10.87 solves the b = 0 condition
    for sign in (1, -1):
        root = -F / 2 + sign * sp.sqrt((16 * (w**2 - 1) / e - 21 * F**2) / 12)
        assert sp.simplify(cos_eq.subs({b: 0}).subs(a, root)) == 0
    # a rotation τ → τ + 2π/3 of the b = 0 solution is the a = −b/√3 one
    vals = {F: sp.Rational(-1, 24), w: sp.Rational(6, 5), e: sp.Rational(1, 10)}
    a0 = (-F / 2 + sp.sqrt((16 * (w**2 - 1) / e - 21 * F**2) / 12)).subs(vals)
    rot = {a: -a0 / 2, b: -a0 * sp.sqrt(3) / 2}
    assert sp.simplify(cos_eq.subs(vals).subs(rot)) == 0
    assert sp.simplify(sin_eq.subs(vals).subs(rot)) == 0


def test_subharmonic_against_true_orbit():
    from lindstedt.analysis.subharmonic import subharmonic

    exists, _, sols = subharmonic(0.1, 0.5, 1.2)
    assert exists and [s.root for s in sols] == ["+", "-"]
    for s in sols:
        assert s.orbit is not None
        assert abs(s.orbit.A[1] - s.a) < 0.02 * abs(s.a)  # first order in ε
        assert abs(s.orbit.A[3] - s.F) < 0.1  # the cos 3τ amplitude, to O(ε)
        assert s.hill_stable == s.orbit.stable  # the notes' claim holds here
    assert [s.orbit.stable for s in sols] == [True, False]
    assert [s.locked for s in sols] == [True, False]  # direct simulation agrees


def test_hill_verdict_fails_for_the_negative_root_at_small_eps(monkeypatch):
    """Reported in the README: the Hill test with q₀ calls the negative root stable here, the
    true orbit's multipliers (at two step sizes) say unstable."""
    import lindstedt.numerics.integrate as integrate
    import lindstedt.numerics.shooting as shooting
    from lindstedt.analysis.subharmonic import subharmonic

    _, _, sols = subharmonic(0.05, 0.5, 1.3)
    minus = sols[1]
    assert minus.root == "-" and minus.hill_stable and not minus.orbit.stable
    for module in (integrate, shooting):  # the flow's steps and the samples they carry
        monkeypatch.setattr(module, "STEPS_PER_PERIOD", 2 * integrate.STEPS_PER_PERIOD)
    _, _, again = subharmonic(0.05, 0.5, 1.3)
    assert not again[1].orbit.stable
    np.testing.assert_allclose(sorted(abs(again[1].orbit.multipliers)),
                               sorted(abs(minus.orbit.multipliers)), rtol=1e-6)


def test_subharmonic_does_not_exist_and_says_why():
    out = run_forked("subharmonic", "--eps", "0.1", "--force", "0.5", "--omega", "0.9", "--json",
                     check=False)
    data = json.loads(out.stdout)
    assert data["exists"] is False and data["solutions"] == [] and "21 F^2" in data["reason"]


# --- frequency mixing -------------------------------------------------------------------------

def test_cubic_mixing_makes_three_fold_combinations_not_sums():
    from lindstedt.analysis.mixing import mixing_series, tone_label

    tones = mixing_series(duffing_table(0.1, 0.1), [(0.3, 1.3), (0.3, 1.7)]).tones
    first = {tone_label(t.combination) for t in tones if t.order <= 1}
    assert first == {"w1", "w2", "3w1", "3w2", "2w1-w2", "2w1+w2", "2w2-w1", "w1+2w2"}
    freqs = [t.frequency for t in tones]
    for nu in (1.3 + 1.7, 1.7 - 1.3):  # ω₁ ± ω₂: absent at every order of a cubic force
        assert all(abs(f - nu) > 1e-9 for f in freqs)


def test_mixing_amplitudes_against_simulated_spectrum():
    out = run_forked("mixing", "--eps", "0.1", "--Q", "10", "--drive", "0.3@1.3", "--drive",
                     "0.3@1.7", "--json", check=False)
    assert out.returncode == 0, out.stderr
    tones = json.loads(out.stdout)["tones"]
    assert {"frequency", "combination", "predicted", "simulated"} <= tones[0].keys()
    for t in tones:
        # the next correction is one order of ε = 0.1 down
        tol = {0: 0.01, 1: 0.05, 2: 0.2}[t["order"]] * t["predicted"] + 2e-6
        assert abs(t["predicted"] - t["simulated"]) <= tol, t
    assert next(t for t in tones if t["combination"] == "2w1-w2")["simulated"] > 5e-3


@pytest.mark.parametrize("eps,force,Q,harmonics,needle", [
    (0.1, 1e6, 185.0, 8, "the limit is 20000"),
    (0.1, 0.3, 20.0, 100_000, "harmonics 100000"),
    (0.1, 0.3, 1e16, 4, "too narrow for the continuation"),
])
def test_continuation_refuses_what_it_cannot_finish(eps, force, Q, harmonics, needle):
    from lindstedt.errors import InputError

    with pytest.raises(InputError, match=needle):
        continue_balance(Drive(eps, force, 0.5, Q).equation, harmonics, 0.5, 2.0)


def test_mixing_bounds_and_escapes():
    from lindstedt.analysis.mixing import mixing_series, simulated_fit
    from lindstedt.errors import InputError

    def simulated(eps, Q, drives):
        table = duffing_table(eps, 1 / Q)
        return simulated_fit(table, drives, list(mixing_series(table, drives).tones))

    with pytest.raises(InputError, match="at most 4"):
        simulated(0.1, 10.0, [(0.1, 1 + k / 10) for k in range(5)])
    with pytest.raises(InputError, match="transients die out"):
        simulated(0.1, 1e12, [(0.3, 1.3)])
    drives = [(3.0, 1.0)]  # softening: driven over the barrier at |q| = 1/√0.1
    with pytest.raises(InputError, match="escapes to infinity"):
        simulated(-0.1, 10.0, drives)
