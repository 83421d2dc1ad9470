"""Limit cycles of q'' + q = ε f(q, q'): the exact L–P series (amplitude fixed order by order)
against the published van der Pol coefficients and against the cycle found numerically
(DOP853, rtol 1e-12: the period between two turns and q there)."""

from __future__ import annotations

import json
from fractions import Fraction as F
from functools import reduce

import numpy as np
import pytest
from lindstedt.cli import main
from lindstedt.derive.cycles import derive_limit_cycle, limit_cycle_amplitudes
from lindstedt.derive.models import oscillator, self_excited_model
from lindstedt.errors import InputError
from scipy.integrate import solve_ivp

VDP = "q'' + q = eps*(1 - q**2)*q'"
LIENARD = "q'' + q = eps*(1 - 5*q**2/4 + q**4/8)*q'"
MIXED = "q'' + q = eps*((1 - q**2)*q' + q**2/3)"
# NOTE: an even term beside van der Pol's: even harmonics and both cos and sin at every order
# NOTE: S(a) = −a(1 − 5a²/16 + a⁴/64): two cycles, a = 2 and a = 4, of opposite stability


def model(text: str):
    return self_excited_model(oscillator(text, name="cycle"))


def numerical_cycle(f, eps: float, q0: float, backwards: bool = False,
                    settle_time: float = 200.0) -> tuple[float, float]:
    """(period, q at the turn q' = 0, q > 0) of the cycle reached from (q0, 0): time to settle
    (the offset decays like exp(−ε S'(a₀) t/2); backwards in time for a repelling cycle), then
    the time between two turns."""
    sign = -1.0 if backwards else 1.0

    def rhs(_t, y):
        q, p = y
        return [sign * p, sign * (-q + eps * f(q, p))]

    settle = solve_ivp(rhs, (0, settle_time), [q0, 0.0], method="DOP853", rtol=1e-12,
                       atol=1e-14)
    start = settle.y[:, -1]

    def turn(_t, y):
        return y[1]
    turn.direction = 1.0 if backwards else -1.0  # q' through zero at a maximum of q

    run = solve_ivp(rhs, (0, 40), start, method="DOP853", rtol=1e-12, atol=1e-14,
                    events=turn, dense_output=True)
    t = run.t_events[0]
    q = run.y_events[0][:, 0]
    assert len(t) >= 3
    return float(t[2] - t[1]), float(q[2])


def test_van_der_pol_against_the_published_coefficients():
    """ω = 1 − ε²/16 + 17ε⁴/3072 + 35ε⁶/884736 − 678899ε⁸/5096079360 …, the amplitude
    2 + ε²/96 − 1033ε⁴/552960 … (Andersen & Geer 1982; the classical values)."""
    lc = derive_limit_cycle(model(VDP), 8)
    assert list(lc.omega) == [1, 0, F(-1, 16), 0, F(17, 3072), 0, F(35, 884736), 0,
                              F(-678899, 5096079360)]
    assert list(lc.amplitude[:5]) == [2, 0, F(1, 96), 0, F(-1033, 552960)]
    assert lc.q[1] == ({}, {1: F(3, 4), 3: F(-1, 4)})  # q₁ = (3 sin s − sin 3s)/4
    assert lc.slope == 2  # S'(2) > 0: attracting for ε > 0


@pytest.mark.parametrize("eps", [0.1, 0.3])
def test_van_der_pol_period_and_amplitude_against_the_numerical_cycle(eps):
    lc = derive_limit_cycle(model(VDP), 24)
    T, q_max = numerical_cycle(lambda q, p: (1 - q * q) * p, eps, 1.0)
    series_T = 2 * np.pi * sum(float(c) * eps**j for j, c in enumerate(lc.period))
    series_q = sum(float(c) * eps**j for j, c in enumerate(lc.amplitude))
    assert series_T == pytest.approx(T, rel=1e-10)
    assert series_q == pytest.approx(q_max, rel=1e-9)


def test_a_quartic_lienard_term_has_two_cycles_of_opposite_stability():
    cycles = limit_cycle_amplitudes(model(LIENARD))
    assert [a for a, _ in cycles] == [2, 4]
    (_, s_inner), (_, s_outer) = cycles
    assert s_inner * s_outer < 0
    eps = 0.05
    f = lambda q, p: (1 - 1.25 * q * q + q**4 / 8) * p  # noqa: E731
    for k, (_, slope) in enumerate(cycles):
        lc = derive_limit_cycle(model(LIENARD), 12, cycle=k)
        # an attracting cycle is reached forwards in time, a repelling one backwards
        rate = eps * abs(float(slope)) / 2  # the offset decays like exp(−rate t)
        T, q_max = numerical_cycle(f, eps, [1.9, 4.1][k], backwards=slope < 0,
                                   settle_time=40 / rate)
        assert 2 * np.pi * sum(float(c) * eps**j for j, c in enumerate(lc.period)) == \
            pytest.approx(T, rel=1e-9)
        assert sum(float(c) * eps**j for j, c in enumerate(lc.amplitude)) == \
            pytest.approx(q_max, rel=1e-8)


def test_rayleigh_has_van_der_pols_frequency():
    """q̈ + q = ε(q̇ − q̇³/3) is van der Pol's equation for q̇ (differentiate): the same ω."""
    assert derive_limit_cycle(model("q'' + q = eps*(q' - q'**3/3)"), 8).omega == \
        derive_limit_cycle(model(VDP), 8).omega


IRRATIONAL = "q'' + q = eps*(q' - q**4*q')"
# NOTE: S(a) = −a/2 + a⁵/16: the cycle at a₀ = 2^(3/4), exact in Q(2^(3/4))


@pytest.mark.parametrize(("text", "f", "a0", "order", "tol"), [
    (IRRATIONAL, lambda q, p: p - q**4 * p, 2**0.75, 12, (1e-10, 1e-10, 1e-6)),
    ("q'' + q = eps*(1 - 2*q**2)*q'", lambda q, p: (1 - 2 * q**2) * p, 2**0.5, 12,
     (1e-10, 1e-9, 1e-4)),
])
def test_an_irrational_amplitude_is_exact_in_its_number_field(text, f, a0, order, tol):
    """a₀ = 2^(3/4) (and √2): the series are exact in Q(a₀), every amplitude coefficient a
    rational multiple of a₀ and every ω_j rational; ω and q(0) against the settled cycle
    (DOP853) at ε = 0.05, 0.2, 0.5."""
    import sympy as sp

    lc = derive_limit_cycle(model(text), order)
    root = sp.nsimplify(a0)
    assert lc.amplitude[0] == root
    assert all(sp.simplify(c / root).is_Rational for c in lc.amplitude if c != 0)
    assert all(getattr(w, "is_Rational", False) or isinstance(w, F) for w in lc.omega)
    for eps, bound in zip((0.05, 0.2, 0.5), tol, strict=True):
        omega = sum(float(c) * eps**j for j, c in enumerate(lc.omega))
        amplitude = sum(float(c) * eps**j for j, c in enumerate(lc.amplitude))
        # started at the series' q(0): the settling (≈ exp(−ε S'(a₀) t/2)) removes what is off
        period, q_turn = numerical_cycle(f, eps, amplitude)
        assert abs(omega - 2 * np.pi / period) < bound, eps
        assert abs(amplitude - q_turn) < bound, eps


def test_an_irrational_cycle_in_the_series_command(capsys):
    assert main(["series", IRRATIONAL, "--order", "4", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["cycles"][0]["amplitude0"] == "2**(3/4)" and data["cycles"][0]["expandable"]
    assert data["amplitude"][:3] == ["2**(3/4)", "0/1", "2**(3/4)/180"]
    assert data["omega"][:3] == ["1/1", "0/1", "-7/48"]


def test_refusals_name_what_is_wrong():
    with pytest.raises(InputError, match="no limit cycle"):
        derive_limit_cycle(model("q'' + q = -eps*q'"), 4)
    with pytest.raises(InputError, match="conservative"):
        model("q'' + q = eps*q**3")
    with pytest.raises(InputError, match="cycle 1"):
        derive_limit_cycle(model(VDP), 2, cycle=1)
    # S(a) ∝ a(a² − 4)²: a double root, a semi-stable cycle (S'(2) = 0)
    with pytest.raises(InputError, match="semi-stable"):
        derive_limit_cycle(model("q'' + q = eps*(1 - 2*q**2 + q**4/2)*q'"), 4)
    with pytest.raises(InputError, match="decays to rest"):  # damping: S(a) = a/2 > 0
        derive_limit_cycle(model("q'' + q + eps*(q' + q**2*q') = 0"), 4)
    with pytest.raises(InputError, match="gains energy"):
        derive_limit_cycle(model("q'' + q = eps*q'"), 4)


def test_the_documented_command_vdp(capsys):
    """`lindstedt series vdp --order K --json` (vdp: the registry's alias of van_der_pol):
    the published first coefficients, the stability of both signs of ε, and partial sums of
    ω against the period of the cycle shot numerically (numerics.true_limit_cycle)."""
    from lindstedt.numerics.shooting import true_limit_cycle

    assert main(["series", "vdp", "--order", "40", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["model"] == "van_der_pol"
    assert data["omega"][:5] == ["1/1", "0/1", "-1/16", "0/1", "17/3072"]
    assert data["stability"].startswith("stable (attracting) for eps > 0, unstable "
                                        "(repelling) for eps < 0")
    omega = [F(c) for c in data["omega"]]
    for eps in (0.1, 0.3):
        cycle = true_limit_cycle(model(VDP), eps)
        partial = sum(float(c) * eps**j for j, c in enumerate(omega))
        assert partial == pytest.approx(2 * np.pi / cycle.period, rel=1e-12, abs=0)


def test_the_alias_is_listed(capsys):
    assert main(["models"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("van_der_pol"))
    assert "(also: vdp)" in line
    assert main(["models", "--json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
    assert rows["van_der_pol"]["aliases"] == ["vdp"] and rows["duffing"]["aliases"] == []


def test_the_series_holds_for_the_repelling_sign_of_eps():
    """ε < 0: the cycle repels, and the same series gives it (traced backwards in time).  With
    an even term beside van der Pol's, q(0) has odd orders: ε and −ε differ."""
    lc = derive_limit_cycle(model(MIXED), 24)
    assert lc.slope > 0 and lc.amplitude[1] != 0
    f = lambda q, p: (1 - q * q) * p + q * q / 3  # noqa: E731
    for eps in (0.15, -0.15):
        T, q_max = numerical_cycle(f, eps, 2.0, backwards=eps < 0)
        assert 2 * np.pi * sum(float(c) * eps**j for j, c in enumerate(lc.period)) == \
            pytest.approx(T, rel=1e-9)
        assert sum(float(c) * eps**j for j, c in enumerate(lc.amplitude)) == \
            pytest.approx(q_max, rel=1e-8)


def test_an_order_beyond_a_minute_is_refused_with_its_estimate(capsys):
    assert main(["series", "vdp", "--order", "3000"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--allow-slow" in err and "order 3000" in err


def test_series_json_of_a_limit_cycle(capsys):
    assert main(["series", "van_der_pol", "--order", "4", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["omega"] == ["1/1", "0/1", "-1/16", "0/1", "17/3072"]
    assert data["amplitude"][:3] == ["2/1", "0/1", "1/96"]
    assert data["q"][1] == {"cos": {}, "sin": {"1": "3/4", "3": "-1/4"}}
    assert data["stable_for"] == "eps > 0"
    assert main(["series", "q'' + q + eps*q' = 0", "--order", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no limit cycle" in err


def test_nearest_singularities_from_the_exact_series(capsys):
    """Van der Pol's ω: a conjugate pair at |ε²| ≈ 3.42 (Andersen & Geer 1982, by Padé from ε²⁴
    exact and ε¹⁶⁴ in floating point) — `series vdp --order 100 --singularities`, within 1 %;
    the free Duffing period's separatrix at x = −1 and the pendulum's at θ₀² = π², on the real
    axis."""
    import math

    from lindstedt.derive.lindstedt import derive, nearest_singularity
    from lindstedt.derive.models import duffing, pendulum

    assert main(["series", "vdp", "--order", "100", "--singularities", "--json"]) == 0
    (vdp,) = json.loads(capsys.readouterr().out)["singularities"]
    assert vdp["variable"] == "eps**2" and vdp["method"] == "Mercer–Roberts"
    assert abs(vdp["radius"] / 3.42 - 1) < 0.01 and vdp["spread"] < 0.05
    assert abs(vdp["radius"] - 3.42) <= vdp["spread"]  # an error bar, 3.42 to its two digits
    assert 0.5 < vdp["angle"] < math.pi - 0.5  # off the real axis
    for m, where, angle in ((duffing(), 1.0, math.pi), (pendulum(40), math.pi**2, 0.0)):
        sol = derive(m, 40)
        est = nearest_singularity([sol.ground.to_fraction(c) for c in sol.period], "y")
        assert est.method == "Domb–Sykes" and est.angle == angle
        assert abs(est.radius / where - 1) < 0.01


def test_true_cycle_and_its_floquet_exponent():
    """Shooting in (q(0), T) from the series' seed: van der Pol's period at ε = 1 is the
    classical 6.6632868593…; the exponent ln|det M|/T equals Liouville's ∮ ε ∂f/∂q̇ dt / T
    integrated along DOP853's cycle, and at small ε the averaged −ε S'(a₀)/2 (opposite signs
    for the Liénard term's two cycles)."""
    from lindstedt.numerics.shooting import true_limit_cycle

    vdp = model(VDP)
    one = true_limit_cycle(vdp, 1.0)
    assert one.period == pytest.approx(6.663286859323, rel=1e-10)
    eps = 0.3
    orbit = true_limit_cycle(vdp, eps)
    assert min(abs(m - 1) for m in orbit.multipliers) < 1e-9  # the phase direction

    def rhs(_t, y):
        q, p, _ = y
        return [p, -q + eps * (1 - q * q) * p, eps * (1 - q * q)]  # ∂f/∂q̇ = 1 − q²

    run = solve_ivp(rhs, (0, orbit.period), [orbit.q0, 0.0, 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-14)
    assert orbit.exponent == pytest.approx(run.y[2, -1] / orbit.period, rel=1e-8)
    lienard = model(LIENARD)
    for k, (_, slope) in enumerate(limit_cycle_amplitudes(lienard)):
        cycle = true_limit_cycle(lienard, 0.01, k)
        assert cycle.exponent == pytest.approx(-0.01 * float(slope) / 2, rel=0.02)


def quick_resummation(monkeypatch) -> None:
    """The resummed evaluators verified on (0, 0.6] with no check points beyond: the partial
    sums, their radius and the derivation do not depend on it, and test_resum tests the
    resummed ones.  (Shooting van der Pol's cycle at each check point up to ε = 10 is 27 of
    the 32 s that `generate van_der_pol --order 16` takes.)"""
    from lindstedt.methods import verify

    monkeypatch.setattr(verify, "RESUM_RANGE", 0.6)
    monkeypatch.setattr(verify, "RESUM_CHECKS", ())


def test_emitted_limit_cycle_module_against_the_true_cycle(tmp_path, monkeypatch):
    """`lindstedt generate van_der_pol`: ω, T, q(0) and q(t) against the shot cycle and
    DOP853 from it, within the module's own error estimate; NaN from 90 % of its estimated
    radius (√3.42 in ε) on."""
    from lindstedt.emit.render import load_generated
    from lindstedt.numerics.shooting import true_limit_cycle

    quick_resummation(monkeypatch)
    assert main(["generate", "van_der_pol", "--order", "16", "--out", str(tmp_path)]) == 0
    mod = load_generated(tmp_path / "van_der_pol.py")
    assert 0.9 * 3.40**0.5 < mod.RADIUS < 0.9 * 3.44**0.5
    assert np.isnan(mod.period(2.0)) and np.isnan(mod.q(0.5, -2.0))
    for eps in (0.1, 0.3, 0.6):
        cycle = true_limit_cycle(model(VDP), eps)
        bound = max(1e-11, 3 * mod.error_estimate(eps))
        assert mod.period(eps) == pytest.approx(cycle.period, rel=bound)
        assert mod.omega(eps) == pytest.approx(2 * np.pi / cycle.period, rel=bound)
        assert mod.amplitude(eps) == pytest.approx(cycle.q0, rel=max(1e-10, 30 * bound))
        t = np.linspace(0.0, cycle.period, 7)
        run = solve_ivp(lambda _t, y, e=eps: [y[1], -y[0] + e * (1 - y[0] ** 2) * y[1]],
                        (0, cycle.period), [cycle.q0, 0.0], method="DOP853", rtol=1e-12,
                        atol=1e-14, t_eval=t)
        np.testing.assert_allclose(mod.q(t, eps), run.y[0], atol=max(1e-9, 30 * bound))


# --- an independent slow route: Fourier dictionaries of Fractions, product-to-sum ------------

def _trig_mul(x: tuple[dict, dict], y: tuple[dict, dict]) -> tuple[dict, dict]:
    """(cos, sin) coefficients of a product: cos a cos b = (cos(a−b) + cos(a+b))/2, …"""
    cos: dict[int, F] = {}
    sin: dict[int, F] = {}

    def add(d, n, v):
        if n < 0:
            n, v = -n, (v if d is cos else -v)
        if n == 0 and d is sin:
            return
        d[n] = d.get(n, F(0)) + v

    for n, a in x[0].items():
        for m, b in y[0].items():
            add(cos, n - m, a * b / 2)
            add(cos, n + m, a * b / 2)
        for m, b in y[1].items():  # cos ns sin ms = (sin(m+n)s + sin(m−n)s)/2
            add(sin, m + n, a * b / 2)
            add(sin, m - n, a * b / 2)
    for n, a in x[1].items():
        for m, b in y[0].items():
            add(sin, n + m, a * b / 2)
            add(sin, n - m, a * b / 2)
        for m, b in y[1].items():  # sin ns sin ms = (cos(n−m)s − cos(n+m)s)/2
            add(cos, n - m, a * b / 2)
            add(cos, n + m, -a * b / 2)
    return ({n: v for n, v in cos.items() if v}, {n: v for n, v in sin.items() if v})


def _trig_add(x, y, c=F(1)):
    out = ({**x[0]}, {**x[1]})
    for part in (0, 1):
        for n, v in y[part].items():
            out[part][n] = out[part].get(n, F(0)) + c * v
    return ({n: v for n, v in out[0].items() if v}, {n: v for n, v in out[1].items() if v})


def _d(x):  # d/ds
    return ({n: n * b for n, b in x[1].items()}, {n: -n * a for n, a in x[0].items()})


def slow_limit_cycle(terms, a0: F, order: int) -> tuple[list[F], list[F]]:
    """ω and q(0) of ω² q'' + q = ε Σ c q^a (ω q')^b, the textbook way: at order j the
    force's [ε^(j−1)] is evaluated twice, with the unknown cos s of q_(j−1) at 0 and at 1 (F_j
    is affine in it); every product a Cauchy sum of Fourier dictionaries (orders below j − 1
    kept, order j − 1 made afresh)."""
    zero = ({}, {})
    one = ({0: F(1)}, {})
    q = [({1: a0}, {})]
    W, omega = [F(1)], [F(1)]
    kept: dict[tuple, tuple] = {}  # (kind, power, n) → coefficient, for n final

    def entry(kind, p, n, last):
        """[ε^n] q^p ("q") or (ω q')^p ("v"); ``last``: q_(j−1) as tried."""
        if (kind, p, n) in kept:
            return kept[kind, p, n]

        def qn(k):
            return last if k == len(q) - 1 else q[k]

        if p == 0:
            out = one if n == 0 else zero
        elif kind == "q" and p == 1:
            out = qn(n)
        elif p == 1:
            out = reduce(lambda acc, k: _trig_add(acc, _d(qn(n - k)), omega[k]),
                         range(n + 1), zero)
        else:
            out = reduce(_trig_add, (_trig_mul(entry(kind, p - 1, k, last),
                                               entry(kind, 1, n - k, last))
                                     for k in range(n + 1)), zero)
        if n < len(q) - 1:
            kept[kind, p, n] = out
        return out

    def F_j(j, last, Wj):
        out = zero
        for a, b, c in terms:
            for k in range(j):
                out = _trig_add(out, _trig_mul(entry("q", a, k, last),
                                               entry("v", b, j - 1 - k, last)), F(c))
        for i in range(1, j):
            out = _trig_add(out, _d(_d(last if j - i == len(q) - 1 else q[j - i])), -W[i])
        return _trig_add(out, ({1: a0 * Wj}, {}))  # −W_j q_0''

    for j in range(1, order + 2):
        base = F_j(j, q[-1], F(0))
        if j >= 2:
            tried = F_j(j, _trig_add(q[-1], ({1: F(1)}, {})), F(0))
            a_prev = -base[1].get(1, F(0)) / (tried[1].get(1, F(0)) - base[1].get(1, F(0)))
            q[-1] = _trig_add(q[-1], ({1: a_prev}, {}))
            base = F_j(j, q[-1], F(0))
        Wj = -base[0].get(1, F(0)) / a0
        W.append(Wj)
        omega.append((Wj - sum((omega[k] * omega[j - k] for k in range(1, j)), F(0))) / 2)
        rhs = _trig_add(base, ({1: a0 * Wj}, {}))
        cos = {n: c / (1 - n * n) for n, c in rhs[0].items() if n != 1}
        sin = {n: c / (1 - n * n) for n, c in rhs[1].items() if n != 1}
        sin[1] = -sum(n * b for n, b in sin.items())  # q_j'(0) = 0
        q.append(({n: v for n, v in cos.items() if v}, {n: v for n, v in sin.items() if v}))
    return omega[: order + 1], [sum(c.values(), F(0)) for c, _ in q[: order + 1]]


@pytest.mark.parametrize(("text", "cycle", "order"), [
    (VDP, 0, 24), (LIENARD, 1, 10), (MIXED, 0, 10),
    ("q'' + q = eps*(1/3 + (1 - q**2)*q' + q*q' + q'**2/5)", 0, 8)])  # every kind of term
def test_the_relaxed_products_against_the_textbook_route(text, cycle, order):
    """Every ω_j and amplitude coefficient exact, against :func:`slow_limit_cycle` (van der Pol
    to order 24: squares of 2, 4 and 8 orders are packed from orders 4, 8 and 16 on)."""
    m = model(text)
    lc = derive_limit_cycle(m, order, cycle)
    a0, _ = limit_cycle_amplitudes(m)[cycle]
    omega, amplitude = slow_limit_cycle(m.terms, a0, order)
    assert list(lc.omega) == omega
    assert list(lc.amplitude) == amplitude


def test_the_derivation_document(tmp_path, monkeypatch):
    """`generate` writes the order-by-order equations beside the module: F_j's sin s and cos s
    vanish with the a_(j−1) and W_j it prints (an exact identity), ω_2 = −1/16 and
    ω_4 = 17/3072 as published, q_j + a_j cos s the series' own q_j; pdflatex compiles it
    without an overfull line.  (Written again it is byte-identical: test_resum's
    test_generated_limit_cycle_module_is_byte_identical compares every file of a second
    generation.)"""
    import shutil
    import subprocess

    lc = derive_limit_cycle(model(VDP), 8)
    a0 = lc.amplitude[0]
    lin_cos, lin_sin = lc.linearisation
    assert [o.j for o in lc.orders] == [1, 2, 3, 4, 5, 6]
    for o in lc.orders:
        a = o.a_prev or 0
        assert o.known[1].get(1, 0) + a * lin_sin.get(1, 0) == 0
        assert o.known[0].get(1, 0) + a * lin_cos.get(1, 0) + a0 * o.W == 0
        nxt = lc.orders[o.j] if o.j < len(lc.orders) else None
        if nxt is not None:
            cos = {**o.q[0], 1: o.q[0].get(1, 0) + nxt.a_prev}
            assert ({n: c for n, c in cos.items() if c}, o.q[1]) == lc.q[o.j]
    assert [o.omega for o in lc.orders[:4]] == [0, F(-1, 16), 0, F(17, 3072)]
    quick_resummation(monkeypatch)
    assert main(["generate", "vdp", "--order", "8", "--out", str(tmp_path / "one")]) == 0
    tex = (tmp_path / "one" / "van_der_pol_derivation.tex").read_text()
    assert r"\omega_{4} = \frac{17}{3072}" in tex and r"W_{2} = -\frac{1}{8}" in tex
    pdflatex = shutil.which("pdflatex")
    if pdflatex is None:
        pytest.skip("pdflatex not installed (`make tex` installs it)")
    run = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error",
                          "van_der_pol_derivation.tex"], cwd=tmp_path / "one",
                         stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=300,
                         check=False)
    assert run.returncode == 0, run.stdout[-2000:]
    log = (tmp_path / "one" / "van_der_pol_derivation.log").read_text(errors="replace")
    assert "Overfull \\hbox" not in log


def test_coefficients_of_any_length_are_printed():
    """Van der Pol's coefficients pass Python's 4300-digit str() limit near order 150; the
    series JSON and table print them whole (digits checked by arithmetic, not by str())."""
    from lindstedt.cli.common import _fraction_text

    for value in (F(7**6000 + 1, 3**12000), F(-(10**5000) - 3, 1), F(-17, 3072)):
        num, den = _fraction_text(value).split("/")
        for text, n in ((num, value.numerator), (den, value.denominator)):
            digits = text.lstrip("-")
            assert text.startswith("-") == (n < 0) and digits.isdigit()
            assert 10 ** (len(digits) - 1) <= abs(n) < 10 ** len(digits)
            head = min(30, len(digits))
            assert int(digits[:head]) == abs(n) // 10 ** (len(digits) - head)
            assert int(digits[-3:]) == abs(n) % 1000


def test_odd_harmonic_sums_round_trip_through_the_kernel():
    """The kernel's C² route for odd harmonics (cos: C·p(C²); sin: S·r(C²), via −d/ds of
    ∫r dC) gives back the Fourier coefficients a sum was built from (Chebyshev's route)."""
    import random

    from lindstedt.algebra.series import Ground, Trig

    g = Ground.for_coefficients([])
    rng = random.Random(3)
    for _ in range(40):
        sums = [{n: F(rng.randint(-50, 50), rng.randint(1, 30))
                 for n in range(1, 2 * rng.randint(1, 12) + 1, 2)} for _ in range(2)]
        t = Trig.from_fourier(*({n: g.scalar(c) for n, c in d.items()} for d in sums), g)
        back = [{n: g.to_fraction(v) for n, v in part.items()} for part in t.to_fourier()]
        assert back == [{n: c for n, c in d.items() if c} for d in sums]


def test_a_cycles_three_amplitudes_are_named_and_each_is_what_it_says(capsys):
    """Rayleigh's cycle: `series` gives q(0) (the displacement where the velocity vanishes,
    2 + 17/96 ε²) and the first harmonic √(A₁² + B₁²) (2 + 9/64 ε²), `slowflow` the averaged
    radius r (2 + 5/64 ε²), each under its own name; q(0) and the first harmonic against the
    cycle DOP853 settles on at ε = 0.1 (their ε⁴ series to ε⁶), r apart from both."""
    eps = 0.1
    assert main(["series", "rayleigh", "--order", "4", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["q0"] == data["amplitude"]
    assert data["q0"][:3] == ["2/1", "0/1", "17/96"]
    assert data["first_harmonic"][:3] == ["2/1", "0/1", "9/64"]
    assert {"q0", "first_harmonic", "slowflow_r"} <= set(data["amplitudes"])
    assert main(["slowflow", "rayleigh", "--order", "3", "--json"]) == 0
    cycle = json.loads(capsys.readouterr().out)["cycles"][0]
    assert cycle["averaged_radius"] == cycle["radius"] == ["2", "0", "5/64"]
    assert "averaged amplitude" in cycle["radius_meaning"]

    def summed(series: list[str]) -> float:
        return sum(float(F(c)) * eps**j for j, c in enumerate(series))

    def rhs(t, y):
        return [y[1], -y[0] + eps * (y[1] - y[1] ** 3 / 3)]

    def turning(t, y):  # q' = 0 falling: q at its maximum
        return y[1]

    turning.direction = -1
    sol = solve_ivp(rhs, (0.0, 200.0), [summed(data["q0"]), 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-14, events=turning, dense_output=True)
    t0, t1 = sol.t_events[0][-2:]
    q0 = sol.y_events[0][-1][0]
    t = np.linspace(t0, t1, 1025)[:-1]
    first = 2 * abs(np.fft.rfft(sol.sol(t)[0])[1]) / len(t)
    assert abs(q0 - summed(data["q0"])) < 1e-5
    assert abs(first - summed(data["first_harmonic"])) < 1e-5
    r = summed(cycle["averaged_radius"])
    assert abs(first - r) > 5e-4 and abs(q0 - r) > 5e-4  # (9/64 − 5/64) ε², (17/96 − 5/64) ε²
