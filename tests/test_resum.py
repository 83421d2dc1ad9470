"""Resummation past the radius of convergence: exact Padé approximants against mpmath's and
against rational functions they must recover, Andersen & Geer's w-variable against its
definition, and the emitted van der Pol evaluators against DOP853 shooting (the literature's
period at ε = 1 checks the shooting first)."""

from __future__ import annotations

from fractions import Fraction as F

import mpmath
import numpy as np
import pytest
from commands import van_der_pol_resummed
from lindstedt.algebra.resum import (
    compose,
    pade,
    real_poles,
    resum_frequency,
    resum_harmonic,
    resum_relaxation,
    resum_series,
    two_point_pade,
    van_der_pol_relaxation,
    w_of,
    w_substitution,
)
from lindstedt.derive.models import series_model
from lindstedt.errors import InputError
from lindstedt.methods import verify as methods
from lindstedt.numerics.references import cycle_reference


def test_pade_recovers_a_rational_function_exactly():
    """(1 + 2x − x²)/(1 − x − 3x²) from its Taylor coefficients (the recurrence
    c_k = c_(k−1) + 3c_(k−2) beyond the numerator): [2/2] is the function itself."""
    c = [F(1), F(3), F(5)]  # c_0 = 1, c_1 = 2 + c_0, c_2 = −1 + c_1 + 3c_0
    for k in range(3, 12):
        c.append(c[k - 1] + 3 * c[k - 2])
    P = pade(c, 2, 2)
    assert P.numerator == (1, 2, -1) and P.denominator == (1, -1, -3)
    assert pade(c, 4, 2).exact(F(1, 7)) == (1 + F(2, 7) - F(1, 49)) / (1 - F(1, 7) - F(3, 49))
    with pytest.raises(InputError, match=r"Padé \[5/4\] in x: singular"):
        pade(c, 5, 4)  # the Padé table's infinite block below [2/2]: no unique denominator


def test_pade_of_log_against_mpmath():
    """[L/M] of log(1 + x)/x against mpmath.pade (its own linear solve at 50 digits)."""
    c = [F((-1) ** k, k + 1) for k in range(21)]
    for L, M in ((10, 10), (9, 10), (6, 5)):
        P = pade(c, L, M)
        with mpmath.workdps(50):
            p, q = mpmath.pade([mpmath.mpf(x.numerator) / x.denominator for x in c], L, M)
            for got, want in ((P.numerator, p), (P.denominator, q)):
                assert [float(x) for x in got] == pytest.approx([float(x) for x in want],
                                                                rel=1e-30, abs=1e-40)
    x = np.array([0.5, 2.0, 9.0])  # [10/10] converges far past the radius |x| = 1
    np.testing.assert_allclose(pade(c, 10, 10)(x), np.log1p(x) / x, rtol=3e-6)


def test_pade_refuses_too_few_coefficients_and_finds_real_poles():
    with pytest.raises(InputError, match=r"Padé \[3/3\]: needs 7 coefficients"):
        pade([F(1)] * 5, 3, 3)
    geometric = pade([F(1, 2**k) for k in range(6)], 2, 1)  # 1/(1 − x/2): a pole at 2
    assert real_poles(geometric, 0, 3) == pytest.approx([2.0])
    assert real_poles(geometric, 0, 1.5) == []


def test_w_substitution_inverts_andersen_geer_w():
    """x(w) from the exact series at w = 0.2 against w(x) = x/(x² − 2px + R²)^½; and the
    composition of a series with it against direct evaluation."""
    R, p = F(17, 5), F(-3, 4)
    xs = w_substitution(R, p, 40)
    w = 0.2
    x = sum(float(c) * w**k for k, c in enumerate(xs))
    assert w_of(np.array(x), float(R), float(p)) == pytest.approx(w, rel=1e-14)
    exp_series = [F(1, int(mpmath.factorial(k))) for k in range(41)]
    composed = compose(exp_series, xs, 40)
    assert sum(float(c) * w**k for k, c in enumerate(composed)) == pytest.approx(
        np.exp(x), rel=1e-12)


def test_two_point_pade_recovers_a_rational_function():
    """(1 + 2v − v²)/(1 − v − 3v²) from two Taylor coefficients at v = 0 and three at v = 1
    (in s = 1 − v: (2 − s²)/(−3 + 7s − 3s²), expanded exactly): [2/2] is the function."""
    c = [F(1), F(3)]  # at v = 0, as in the one-point test above
    d = [F(-2, 3)]  # (2 − s²)/(−3 + 7s − 3s²) = Σ d_j s^j: −3d_j + 7d_(j−1) − 3d_(j−2) = n_j
    for j, n in ((1, 0), (2, -1)):
        d.append((n - 7 * d[j - 1] + 3 * (d[j - 2] if j >= 2 else 0)) / -3)
    P = two_point_pade(c, d, 2, 2)
    for got, want in zip((*P.numerator, *P.denominator), (1, 2, -1, 1, -1, -3), strict=True):
        assert abs(got - want) < F(1, 10**200)
    with pytest.raises(InputError, match=r"needs 4 coefficients at 0"):
        two_point_pade(c, d[:1], 2, 2)


def test_relaxation_constants_against_mpmath():
    """Dorodnitsyn's a = 3 − 2 ln 2 and b = 3·2.338107… (the first zero of Ai(−x)) against
    mpmath at 50 digits."""
    r = van_der_pol_relaxation()
    with mpmath.workdps(50):
        for got, want in ((r.a, 3 - 2 * mpmath.log(2)), (r.b, -3 * mpmath.airyaizero(1))):
            assert abs(mpmath.mpf(got.mid().str(60, radius=False)) - want) < mpmath.mpf(10) ** -45
    assert r.c == F(-2, 3)


def test_relaxation_form_reaches_the_relaxation_regime():
    """From the order-60 series: the relaxation form (resum_relaxation) within 3e-4 of DOP853
    shooting (rtol 1e-9: ~1e-8) at ε = 10 and 1e-5 at ε = 5, and at ε = 10 over ten times
    closer than Padé in w of the same coefficients (resum_frequency); 1e-7 at ε = 10 needs
    order 164 (benchmarks/resum_relaxation.py; ε ≤ 1: the emitted module's test below)."""
    from lindstedt.derive.cycles import derive_limit_cycle
    from lindstedt.derive.lindstedt import nearest_singularity

    lc = derive_limit_cycle(series_model("van_der_pol", 60), 60)
    est = nearest_singularity(lc.omega)
    form = resum_relaxation(lc.omega, est.radius, est.angle, van_der_pol_relaxation())
    plain = resum_frequency(lc.omega, est.radius, est.angle)
    assert form.log is not None and form.spread(10.0) < 1e-3
    for eps, tol in ((5.0, 1e-5), (10.0, 3e-4)):
        omega = 2 * np.pi / cycle_reference(lc.model, eps, rtol=1e-9).period
        error = abs(float(form(eps)) / omega - 1)
        assert error < tol
        if eps == 10.0:
            assert abs(float(plain(eps)) / omega - 1) > 10 * error


def test_even_series_are_read_in_the_square():
    """1/(1 + q²) = Σ (−1)^k q^(2k): Padé in q², exact, no pole on the real axis."""
    r = resum_series([F((-1) ** (k // 2)) if k % 2 == 0 else F(0) for k in range(9)], 10.0)
    assert r.power == 2
    assert float(r(3.0)) == pytest.approx(0.1, rel=1e-15)


def test_the_shooting_reference_against_the_literature():
    """T(ε = 1) = 6.66328685932313 (van der Pol, many sources) and T(10) = 19.0784 (the
    relaxation oscillation, e.g. Andersen & Geer's table)."""
    vdp = series_model("van_der_pol", 4)
    one = cycle_reference(vdp, 1.0)
    assert one.period == pytest.approx(6.663286859323130, rel=1e-13)
    assert one.accuracy < 1e-12
    assert cycle_reference(vdp, 10.0, rtol=1e-9).period == pytest.approx(19.0784, rel=1e-5)


@pytest.fixture(scope="module")
def emitted(run_folder):
    """The module `lindstedt generate van_der_pol --order 12 --resum-order 60` writes (partial
    sums to order 12, ω resummed from its series to order 60: the relaxation form is then
    verified to |ε| ≈ 3.75), with fewer shooting checks, and its folder (made once a run:
    tests/test_emitted_safety.py loads it too)."""
    from lindstedt.emit.render import load_generated

    folder = van_der_pol_resummed(run_folder)
    return load_generated(folder / "van_der_pol.py"), folder


def test_emitted_resummed_frequency_against_shooting(emitted):
    """omega_resummed, period_resummed and amplitude_resummed within 1e-12 of DOP853 shooting
    for ε ≤ 1 (the series alone stops at 0.9·√3.42 = 1.66) and within 1e-6 up to the verified
    limit; NaN beyond it; the error estimate is below the tolerance there."""
    mod, folder = emitted
    assert 3.5 < mod.RESUMMED_LIMIT < 4.5
    # the partial sums stop at 12, the resummed form uses all 31 terms in ε² of order 60
    assert mod.ORDER == 12 and len(mod.OMEGA_EXACT) == 13 and mod.RESUMMED_DEGREES == (17, 16)
    assert "--order 12 --resum-order 60" in (folder / "van_der_pol.py").read_text()
    vdp = series_model("van_der_pol", 4)
    for eps, tol in ((0.1, 1e-12), (1.0, 1e-12), (2.5, 1e-6), (mod.RESUMMED_LIMIT, 1e-6)):
        ref = cycle_reference(vdp, eps)
        assert mod.period_resummed(eps) == pytest.approx(ref.period, rel=tol)
        assert mod.omega_resummed(-eps) == pytest.approx(2 * np.pi / ref.period, rel=tol)
        assert mod.resummed_error(eps) < 1e-6
        if eps <= mod.AMPLITUDE_RESUMMED_LIMIT:
            assert mod.amplitude_resummed(eps) == pytest.approx(ref.q0, rel=tol)
    assert np.isnan(mod.omega(1.8)) and np.isnan(mod.amplitude(1.8))  # the series' guard
    assert mod.AMPLITUDE_RESUMMED_LIMIT > 2.5 and np.isnan(mod.amplitude_resummed(5.0))
    assert np.all(np.isnan(mod.omega_resummed(np.array([mod.RESUMMED_LIMIT + 1e-9, 5.0, 10.0,
                                                          np.nan]))))


def test_harmonic_form_recovers_functions_rational_in_w():
    """With R = 1, R cos β = −1, w = ε²/(1 + ε²): 1/(1 + ε²) = 1 − w and ε(1 − ε²)/(1 + ε²)²
    = ε(1 − w)(1 − 2w) are rational in w, so the Padé in w of their series (13 terms, radius
    1) must give them on all of ε ≥ 0; the odd one through ε times an even series."""
    even = [F((-1) ** (k // 2)) if k % 2 == 0 else F(0) for k in range(13)]
    # ε(1 − ε²)/(1 + ε²)² = Σ (−1)^k (2k + 1) ε^(2k+1)
    odd = [F((-1) ** (k // 2) * k) if k % 2 else F(0) for k in range(13)]
    e = np.array([0.1, 1.0, 3.0, 10.0, 100.0])
    f, g = resum_harmonic(even, F(1), F(-1)), resum_harmonic(odd, F(1), F(-1))
    assert not f.odd and g.odd
    np.testing.assert_allclose(f(e), 1 / (1 + e**2), rtol=1e-12)  # 1 − w: 4 digits at 100
    np.testing.assert_allclose(g(e), e * (1 - e**2) / (1 + e**2) ** 2, rtol=1e-12, atol=1e-15)
    with pytest.raises(InputError, match="even in ε"):
        resum_harmonic([F(1), F(1), F(1), F(1)], F(1), F(-1))


def test_emitted_relaxation_form_equals_the_in_process_one(emitted):
    """The module's omega_resummed (cube root by scaled Halley steps, ln s by the atanh series,
    Estrin's split) against the same form evaluated with NumPy's cbrt and log1p: the same
    function to 3e-14 (the Padé's rounding near the verified limit), its twin to 2 ulp."""
    from lindstedt.derive.cycles import derive_limit_cycle
    from lindstedt.derive.lindstedt import nearest_singularity

    mod, _ = emitted
    omega = derive_limit_cycle(series_model("van_der_pol", 60), 60).omega
    est = nearest_singularity(omega)
    form = resum_relaxation(omega, est.radius, est.angle, van_der_pol_relaxation())
    e = np.linspace(1e-3, mod.RESUMMED_LIMIT, 2001)
    value = mod.omega_resummed(e)
    np.testing.assert_allclose(value, form(e), rtol=3e-14)
    np.testing.assert_array_max_ulp(mod.omega_resummed_into(np.empty_like(e), e), value, 2)


def test_emitted_resummed_q_against_the_shot_orbit(emitted):
    """q_resummed(t, eps) over three periods against DOP853 from the shot cycle's maximum:
    ≤ 1e-11 at ε = 1 (where the order-12 partial sum is 4e-4 off), within the module's
    tolerance of max |q| at its verified limit, which lies past the partial sums' 0.9·√R;
    NaN beyond it."""
    from scipy.integrate import solve_ivp

    mod, _ = emitted
    limit = mod.Q_RESUMMED_LIMIT
    assert limit > mod.RADIUS and mod.Q_RESUMMED_ERROR <= mod.RESUMMED_TOLERANCE
    vdp = series_model("van_der_pol", 4)
    for eps, tol in ((1.0, 1e-11), (limit, 2 * mod.RESUMMED_TOLERANCE)):  # of max |q|
        ref = cycle_reference(vdp, eps)
        t = np.linspace(0.0, 3 * ref.period, 61)
        run = solve_ivp(lambda _t, y, e=eps: [y[1], -y[0] + e * (1 - y[0] ** 2) * y[1]],
                        (0.0, t[-1]), [ref.q0, 0.0], method="DOP853", rtol=1e-13,
                        atol=1e-14, t_eval=t)
        assert np.max(np.abs(mod.q_resummed(t, eps) - run.y[0])) <= tol * np.max(np.abs(run.y[0]))
    assert np.all(np.isnan(mod.q_resummed(0.0, np.array([limit + 1e-9, 10.0, np.nan]))))


def test_resum_order_is_refused_where_it_means_nothing(tmp_path, capsys):
    """--resum-order below the order + 2 the error estimate needs, on a module without a
    limit cycle, on an oscillator without one, negative, on a cycle whose ω(ε) is not resummed
    (rather than a module without the resummed evaluators asked for): one line, exit 2,
    nothing written."""
    from lindstedt.cli import main

    for args, words in (
            (["van_der_pol", "--order", "12", "--resum-order", "13"], "at least the order + 2"),
            (["duffing", "--resum-order", "60"], "duffing has no limit cycle"),
            (["driven", "--resum-order", "60"], "no limit cycle to resum"),
            (["q'' + q + eps*q**3 = 0", "--resum-order", "60"], "has no limit cycle"),
            (["van_der_pol", "--resum-order", "-1"], "--resum-order"),
            # a cycle whose ω(ε) has a real singularity (Domb–Sykes): asked for, not resummed
            (["q'' + q = eps*(1 - q**2)*q' + eps*q**2", "--order", "6", "--resum-order", "30"],
             "ω(ε) is not resummed: ω's nearest singularity is estimated by Domb–Sykes")):
        try:
            code = main(["generate", *args, "--out", str(tmp_path / "x")])
        except SystemExit as exc:  # argparse's own refusals
            code = exc.code
        err = capsys.readouterr().err.strip()
        assert code == 2 and words in err.splitlines()[-1], (args, err)
        assert not (tmp_path / "x").exists()


def test_generated_limit_cycle_module_is_byte_identical(emitted, tmp_path):
    """A second, independent generation (through the API, in this process) writes the same
    bytes as the command line's."""
    from lindstedt.compiler import generate_limit_cycle

    _, folder = emitted
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(methods, "RESUM_CHECKS", (1.0, 2.0))
        again = generate_limit_cycle(series_model("van_der_pol", 14), 12, tmp_path,
                                     resum_order=60)
    assert sorted(p.name for p in again) == sorted(p.name for p in folder.iterdir()
                                                   if p.is_file())
    for p in again:
        assert p.read_bytes() == (folder / p.name).read_bytes(), p.name


def test_mathieu_reference_against_dlmf_and_mpmath():
    """The eigenvalue reference at q = 1 against Abramowitz & Stegun's Table 20.1 (8 decimals:
    a_0 = −0.45513860, a_1 = 1.85910807, b_1 = −0.11024882, b_2 = 3.91702477), and float64
    against mpmath at 30 digits at q = 40."""
    from lindstedt.numerics.references import mathieu_reference

    for kind, m, value in (("a", 0, -0.45513860), ("a", 1, 1.85910807),
                           ("b", 1, -0.11024882), ("b", 2, 3.91702477)):
        assert mathieu_reference(kind, m, 1.0) == pytest.approx(value, abs=6e-9)
    for kind, m in (("a", 0), ("a", 3), ("b", 6)):
        exact = mathieu_reference(kind, m, 40.0, dps=30)
        assert mathieu_reference(kind, m, 40.0) == pytest.approx(exact, rel=1e-14)


def test_mathieu_refined_and_truncation_bound_against_mpmath():
    """The fast 30-digit reference (float64 eigenvalue + mpmath Newton on the determinant)
    against mpmath's own symmetric eigensolver at 40 digits (60 rows), and the truncation
    bound against the true change of the eigenvalue when the matrix is cut to N rows."""
    import mpmath
    from lindstedt.numerics.references import (
        mathieu_recurrence,
        mathieu_refined,
        mathieu_truncation_bound,
    )

    def eigsy(kind, m, q, n):
        index, diag, couplings = mathieu_recurrence(kind, m, n)
        with mpmath.workdps(40):
            A = mpmath.zeros(n, n)
            for i, (r2, s) in enumerate(diag):
                A[i, i] = r2 + s * mpmath.mpf(q)
            for i, t in enumerate(couplings):
                A[i, i + 1] = A[i + 1, i] = mpmath.sqrt(t) * mpmath.mpf(q)
            return sorted(mpmath.eigsy(A, eigvals_only=True))[index]

    for kind, m, q in (("a", 0, 3.0), ("b", 1, 40.0), ("a", 6, 25.0), ("b", 6, 32.0)):
        exact = eigsy(kind, m, q, 60)
        with mpmath.workdps(40):
            assert abs(mathieu_refined(kind, m, q) - exact) <= 1e-27 * max(1, abs(exact))
        for n in (8, 10, 12, 14):
            bound = mathieu_truncation_bound(kind, m, q, float(exact), n)
            assert abs(eigsy(kind, m, q, n) - exact) <= bound


@pytest.mark.parametrize(("kind", "m", "past"), [("a", 0, 2.0), ("a", 3, 1.0), ("b", 6, 5.0)])
def test_emitted_mathieu_against_the_eigenvalue_reference(kind, m, past, tmp_path):
    """`lindstedt mathieu KIND --m M --order 60 --out DIR`: the ufunc within 1e-15·max(1,
    |a|) (a few units in the last place) of the mpmath eigenvalues at 30 digits inside its
    verified q, past the series' radius (|q| ≈ 1.47 for a_0), NaN beyond (and below q = 0 for
    a series with odd powers); the error estimate (the Newton step) covers the error."""
    from lindstedt.cli import main
    from lindstedt.emit.render import load_generated
    from lindstedt.numerics.references import mathieu_reference

    assert main(["mathieu", kind, "--m", str(m), "--order", "60", "--out",
                 str(tmp_path)]) == 0
    mod = load_generated(tmp_path / f"mathieu_{kind}{m}.py")
    f, estimate = getattr(mod, f"{kind}{m}"), getattr(mod, f"{kind}{m}_error")
    assert past < mod.LIMIT
    for q in np.linspace(0.1, mod.LIMIT, 9):
        exact = mathieu_reference(kind, m, float(q), dps=30)
        assert abs(f(q) - exact) <= 1e-15 * max(1.0, abs(exact))
        assert 0 <= estimate(q) <= 1e-9
    assert np.isnan(f(mod.LIMIT + 0.01)) and np.isnan(f(np.nan))
    assert np.isnan(estimate(mod.LIMIT + 0.01))
    assert np.isnan(f(-0.5)) != mod.SYMMETRIC


def test_mathieu_emit_refuses_bad_input(tmp_path, capsys):
    from lindstedt.cli import main

    assert main(["mathieu", "b", "--m", "0", "--order", "60", "--out", str(tmp_path)]) == 2
    assert "b_0 does not exist" in capsys.readouterr().err
    assert main(["mathieu", "a", "--m", "1", "--order", "2", "--out", str(tmp_path)]) == 2
    assert list(tmp_path.iterdir()) == []


def test_choose_mathieu_weighs_series_pade_and_the_solver():
    """Past the series' radius (q = 2 > 1.47) the partial sums miss; the Padé evaluator meets
    1e-13 against mpmath and is the cheapest; on (0, 45], where it is NaN, the solver wins."""
    from lindstedt.choose import choose_mathieu

    near = choose_mathieu("a", 0, 1e-13, 0.0, 2.0, order=60, points=5)
    rows = {m: e for m, _, e, _, _ in near.considered}
    assert near.method == "pade" and rows["series"] > 1e-3 and rows["pade"] <= 1e-13
    far = choose_mathieu("a", 0, 1e-13, 0.0, 45.0, order=60, points=5)
    assert far.method == "reference" and far.max_error <= 1e-14
    with pytest.raises(InputError, match="no method meets it"):  # the Padé value is NaN past
        # q ≈ 7 and the refined one can equal the 30-digit reference at a few points
        choose_mathieu("a", 0, 1e-30, 0.0, 45.0, order=60, points=5)


def test_generated_mathieu_module_is_byte_identical(tmp_path):
    from lindstedt.compiler import generate_mathieu

    first = generate_mathieu("b", 3, 40, tmp_path / "one")
    second = generate_mathieu("b", 3, 40, tmp_path / "two")
    assert [p.name for p in first] == ["mathieu_b3.py"]
    assert first[0].read_bytes() == second[0].read_bytes()


def test_mathieu_start_is_the_cheapest_verified_as_far(tmp_path, monkeypatch):
    """a_1 (odd powers of q) to order 100: the emitted start is a Padé of fewer degrees than
    the order-100 one, verified at least as far as the order-100 start holds 1e-9 against
    mpmath (less one grid step); the ufunc is within 1e-15·max(1, |a|) of mpmath's
    eigenvalues at 30 digits up to its limit."""
    from lindstedt.compiler import generate_mathieu
    from lindstedt.derive.hill import mathieu_series
    from lindstedt.emit.render import load_generated
    from lindstedt.numerics.references import mathieu_reference, mathieu_refined

    starts = {}  # resum_series of each truncation the generator weighs, by its length

    def weighed(coefficients, *args):
        starts[len(coefficients)] = form = resum_series(coefficients, *args)
        return form

    monkeypatch.setattr(methods, "resum_series", weighed)
    generate_mathieu("a", 1, 100, tmp_path)
    mod = load_generated(tmp_path / "mathieu_a1.py")
    # the order-100 start, a pure function of the whole series: kept, not computed again
    # (its [50/50] Padé over QQ is a third of the test's time)
    full = starts[len(mathieu_series("a", 1, 100))]
    assert full.power == 1 and not mod.SYMMETRIC
    assert sum(mod.DEGREES) < sum(full.approximant.degrees) == 100
    step = methods.MATHIEU_RANGE / methods.MATHIEU_GRID
    grid = np.arange(1, methods.MATHIEU_GRID + 1) * step
    ref = np.array([float(mathieu_refined("a", 1, float(q))) for q in grid[grid <= 6.0]])
    miss = np.abs(full(grid[: ref.size]) - ref) / np.maximum(1.0, np.abs(ref)) \
        > methods.MATHIEU_START_TOLERANCE
    full_limit = grid[int(np.argmax(miss)) - 1]
    assert miss.any() and full_limit - step <= mod.LIMIT
    for q in np.linspace(0.05, mod.LIMIT, 7):
        exact = mathieu_reference("a", 1, float(q), dps=30)
        assert abs(mod.a1(q) - exact) <= 1e-15 * max(1.0, abs(exact))
