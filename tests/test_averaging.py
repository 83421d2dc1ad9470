"""The slow flow (lindstedt.derive.averaging) against independent references: the literature's
van der Pol flow, the L–P limit cycles (exact), harmonic balance for the driven Duffing, and SciPy's
DOP853 simulation of the equation itself (the error's order in ε)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from lindstedt.analysis.driven import Drive, harmonic_balance, one_harmonic_roots
from lindstedt.derive.averaging import PHI, R, cycle_series, fixed_points, slow_flow, transient
from lindstedt.derive.cycles import derive_limit_cycle
from lindstedt.derive.models import oscillator, self_excited_model
from lindstedt.errors import InputError
from scipy.integrate import solve_ivp

VDP = "q'' + q = eps*(1 - q**2)*q'"
RAYLEIGH = "q'' + q = eps*(q' - q'**3/3)"
DAMPED_DUFFING = "q'' + 2*eps*zeta*q' + q + eps*q**3 = 0"
DRIVEN = "q'' + q = eps*(-k*q' - q**3 + F*cos(w*t))"
LIENARD = "x'' + x = eps*((1/4 - x**2)*x' - x**3 + x*x'**2)"
# NOTE: a user's Liénard-type equation, conservative terms beside the self-excited one (a0 = 1)
EPS = sp.Symbol("eps")


def test_van_der_pol_first_and_second_order_flow():
    """r' = ε r/2 (1 − r²/4), φ' = 0 at first order (Rand, *Lecture Notes on Nonlinear
    Vibrations*, §5); no ε² term in r', and the cycle's frequency 1 − ε²/16 (Andersen & Geer)."""
    flow = slow_flow(oscillator(VDP), 2)
    assert sp.expand(flow.radial[0] - (R / 2 * (1 - R**2 / 4))) == 0
    assert flow.phase[0] == 0
    assert flow.radial[1] == 0
    assert flow.phase[1].subs(R, 2) == sp.Rational(-1, 16)


def test_one_oscillator_is_the_one_mode_case_of_the_record():
    """One mode, ω₀ = 1, the symbols r, φ: da/dt = dr/dt = Σ ε^k R_k and the rates are
    (dr/dt, dφ/dt); the system-only fields are empty, and a system's flow is refused where
    (r, φ) is meant."""
    from lindstedt.derive.system import parse_system

    flow = slow_flow(oscillator(VDP), 3)
    assert flow.a == (R,) and flow.phi == (PHI,) and flow.modes == (1,) and flow.system is None
    assert flow.amplitude == (sum(EPS ** (k + 1) * flow.radial[k] for k in range(3)),)
    assert flow.rates == (*flow.amplitude, sum(EPS ** (k + 1) * flow.phase[k] for k in range(3)))
    system = slow_flow(parse_system("x'' + x + x*y = 0; y'' + 4*y + x**2 = 0"), 1)
    assert len(system.cartesian[0]) == 4 and system.transform == ()
    for use in (lambda: cycle_series(system), lambda: fixed_points(system, 0.1)):
        with pytest.raises(InputError, match="one oscillator's slow flow"):
            use()


def _omega_series(flow, a0) -> list[sp.Rational]:
    """ω = 1 + dφ/dt at the root r* = a0 + ε r1 + … of dr/dt, as a series in ε (exact):
    r_i from the ε^i part of (dr/dt)/ε, linear in r_i with slope R_1'(a0)."""
    N = flow.order

    def truncated(expr):
        return sum(sp.expand(expr).coeff(EPS, i) * EPS**i for i in range(N + 1))

    slope = sp.diff(flow.radial[0], R).subs(R, a0)
    rstar = sp.Integer(a0)
    for i in range(1, N):
        radial = truncated(sum(EPS**k * sp.expand(flow.radial[k].subs(R, rstar))
                               for k in range(N)))
        rstar = rstar - radial.coeff(EPS, i) / slope * EPS**i
    phase = truncated(sum(EPS ** (k + 1) * sp.expand(flow.phase[k].subs(R, rstar))
                          for k in range(N)))
    return [sp.Integer(1)] + [phase.coeff(EPS, k) for k in range(1, N + 1)]


@pytest.mark.parametrize("text", [VDP, RAYLEIGH, LIENARD])
def test_limit_cycle_frequency_matches_lindstedt_to_the_order(text):
    """The fixed point's phase rate gives ω to ε^N exactly: the L–P series (another derivation,
    the secular conditions at fixed period) holds the same rationals."""
    osc = oscillator(text)
    lc = derive_limit_cycle(self_excited_model(osc), 4)
    flow = slow_flow(osc, 4)
    omega = _omega_series(flow, sp.Rational(lc.amplitude[0]))
    assert omega == [sp.Rational(w) for w in lc.omega]
    if text == VDP:
        assert omega == [1, 0, sp.Rational(-1, 16), 0, sp.Rational(17, 3072)]
    (cycle,) = cycle_series(flow)
    assert list(cycle.omega) == omega and cycle.radius[0] == lc.amplitude[0]
    assert cycle.slope == -sp.Rational(lc.slope) / 2  # R_1 = −S/2, S of L–P: one stability


def _cycle_amplitude(flow, eps: float) -> float:
    """q(0) with q̇(0) = 0 on the slow flow's cycle: the curve x = y* + Σ ε^j w_j(y*, τ) of the
    phase plane (autonomous: the orbit depends on τ + φ only), its largest q."""
    (rstar, _), = fixed_points(flow, eps)
    tau = sp.Symbol("tau")
    U, V = sp.Symbol("_u"), sp.Symbol("_v")
    ws = [sp.lambdify(tau, sp.sympify(sum(eps ** (j + 1) * w[i]
                                          for j, w in enumerate(flow.transform)))
                      .subs({U: rstar, V: 0}) + 0 * tau, "numpy") for i in range(2)]

    def q(t):
        return (rstar + ws[0](t)) * np.cos(t) + ws[1](t) * np.sin(t)

    t = np.linspace(-0.5, 0.5, 20001)
    return float(np.max(q(t)))


@pytest.mark.parametrize("order", [1, 2, 3])
def test_limit_cycle_amplitude_error_is_of_the_order(order):
    """The cycle's amplitude from the slow flow and its transformation against L–P's q(0)
    (order 12, converged at these ε): the error falls at least 2^N-fold when ε halves (van der
    Pol's amplitude has no ε¹ term, so order 1 is already O(ε²))."""
    osc = oscillator(VDP)
    lc = derive_limit_cycle(self_excited_model(osc), 12)
    flow = slow_flow(osc, order)
    errors = []
    for eps in (0.1, 0.05):
        reference = sum(float(a) * eps**j for j, a in enumerate(lc.amplitude))
        errors.append(abs(_cycle_amplitude(flow, eps) - reference))
    ratio = errors[0] / errors[1]
    assert ratio > 2**order * 0.7, (errors, ratio)
    assert errors[0] < 0.1**order, errors


def _simulate(text: str, values: dict, eps: float, q0: float, p0: float, times: np.ndarray
              ) -> np.ndarray:
    """The equation itself, integrated by DOP853 at rtol 1e-12: (q, q̇) at ``times``.  The
    right side is lambdified from SymPy's own parse of the text (not the package's)."""
    lhs, rhs = text.split("=")
    q, v, a, t = sp.symbols("q v a t")
    names = {"q''": "a", "q'": "v"}
    for key in ("q''", "q'"):
        lhs, rhs = lhs.replace(key, names[key]), rhs.replace(key, names[key])
    local = {"q": q, "v": v, "a": a, "t": t, "eps": sp.Float(eps)}
    local.update({k: sp.Float(x) for k, x in values.items()})
    expr = sp.sympify(lhs, locals=local) - sp.sympify(rhs, locals=local)
    accel = sp.solve(expr, a)[0]
    f = sp.lambdify((t, q, v), accel, "math")
    sol = solve_ivp(lambda s, y: (y[1], f(s, y[0], y[1])), (0, times[-1]), (q0, p0),
                    method="DOP853", t_eval=times, rtol=1e-12, atol=1e-14)
    return sol.y


def _transient_errors(text, values, order, q0, horizon, eps_values=(0.1, 0.05)):
    flow = slow_flow(oscillator(text), order)
    errors = []
    for eps in eps_values:
        times = np.linspace(0, horizon / eps, 2001)
        sim = _simulate(text, values, eps, q0, 0.0, times)
        pred = transient(flow, eps, q0, 0.0, times, values)
        errors.append(np.max(np.abs(np.hypot(*sim) - np.hypot(*pred))))
    return errors


@pytest.mark.parametrize("order", [1, 2])
def test_van_der_pol_growth_onto_the_cycle(order):
    """From r = 0.1 onto the cycle r = 2 (εt ≤ 8): the amplitude √(q² + q̇²) of the simulation
    and of the slow flow differ by O(ε^N), N its order."""
    e1, e2 = _transient_errors(VDP, {}, order, 0.1, 8.0)
    assert e1 < (0.1 if order == 1 else 0.01)
    assert 2**order * 0.7 < e1 / e2 < 2**order * 1.45, (e1, e2)


@pytest.mark.parametrize("order", [1, 2])
def test_damped_duffing_decay(order):
    """q'' + 2εζq' + q + εq³ = 0 from q = 1 (εt ≤ 3, ζ = 1/4): the decay within O(ε^N)."""
    text = DAMPED_DUFFING.replace("zeta", "(1/4)")
    e1, e2 = _transient_errors(text, {}, order, 1.0, 3.0)
    assert 2**order * 0.7 < e1 / e2 < 2**order * 1.45, (e1, e2)
    flow = slow_flow(oscillator(text), 1)
    assert sp.expand(flow.radial[0] + R / 4) == 0  # r' = −ζ r ε: the linear decay rate


def test_damped_duffing_keeps_zeta_symbolic():
    flow = slow_flow(oscillator(DAMPED_DUFFING), 2)
    zeta = sp.Symbol("zeta")
    assert flow.parameters == (zeta,)
    assert sp.expand(flow.radial[0] + zeta * R) == 0
    assert sp.expand(flow.phase[0] - sp.Rational(3, 8) * R**2) == 0  # 1 + 3εa²/8


@pytest.mark.parametrize("sigma", [-0.5, 0.5, 1.5])
def test_driven_fixed_points_are_the_steady_states(sigma):
    """q'' + q = ε(−k q' − q³ + F cos ωt), ω = 1 + εσ: the fixed points of the slow flow against
    harmonic balance with 9 odd harmonics (driven.harmonic_balance, eq. 10.60 with ε_D = ε,
    1/Q = εk, f = εF) and the one-harmonic roots: the first harmonic's amplitude agrees to
    O(ε²) at order 2 (ratio ≈ 4 when ε halves)."""
    k, F = 0.5, 1.0
    values = {"k": k, "F": F, "sigma": sigma}
    flows = {n: slow_flow(oscillator(DRIVEN), n) for n in (1, 2)}
    errors = {1: [], 2: []}
    for eps in (0.04, 0.02):
        w = 1 + eps * sigma
        roots = one_harmonic_roots(eps, eps * F, 1 / (eps * k), np.array([w]))[0]
        roots = np.sqrt(roots[np.isfinite(roots)])
        d = Drive(eps, eps * F, w, 1 / (eps * k))
        for n, flow in flows.items():
            guesses = tuple((r, p) for r in roots for p in np.linspace(-3, 3, 7))
            found = fixed_points(flow, eps, values, guesses)
            for r in roots:
                (rs, ps) = min(found, key=lambda x, r=r: abs(x[0] - r))
                hb = harmonic_balance(d, np.array([rs * math.cos(ps), -rs * math.sin(ps)]), 9)
                assert hb.converged
                M = (len(hb.coefficients) - 1) // 2
                first = 2 * abs(hb.coefficients[M + 1])
                predicted = _first_harmonic(flow, eps, values, rs, ps)
                errors[n].append(abs(predicted - first))
                if n == 1:
                    assert abs(rs - r) < 5 * eps * r  # the one-harmonic root, to O(ε)
    for n in (1, 2):
        half = len(errors[n]) // 2
        ratio = max(errors[n][:half]) / max(errors[n][half:])
        assert 2**n * 0.6 < ratio < 2**n * 1.6, (n, errors[n])


def _first_harmonic(flow, eps, values, rs, ps) -> float:
    """|first harmonic| of q(τ) = x_u cos τ + x_v sin τ on the steady orbit
    x = y* + Σ ε^j w_j(y*, τ), by the trapezoidal rule (exact for trigonometric polynomials)."""
    tau = sp.Symbol("tau")
    U, V = sp.Symbol("_u"), sp.Symbol("_v")
    subs = {sp.Symbol(k): v for k, v in values.items()}
    subs.update({U: rs * math.cos(ps), V: -rs * math.sin(ps)})
    t = np.linspace(0, 2 * np.pi, 256, endpoint=False)
    x = [rs * math.cos(ps) + 0 * t, -rs * math.sin(ps) + 0 * t]
    for j, w in enumerate(flow.transform):
        for i in range(2):
            x[i] = x[i] + eps ** (j + 1) * sp.lambdify(tau, w[i].subs(subs) + 0 * tau)(t)
    q = x[0] * np.cos(t) + x[1] * np.sin(t)
    return float(2 * abs(np.mean(q * np.exp(-1j * t))))


def test_driven_flow_in_the_rotating_frame():
    """First order: the classical frequency-response equations of the forced Duffing
    (Nayfeh & Mook, eq. 4.1.15 with their μ = k/2, α = 1, k = F): r' = −k r/2 − F sin φ/2,
    φ' = −σ + 3r²/8 − F cos φ/(2r)."""
    flow = slow_flow(oscillator(DRIVEN), 1)
    k, F, sigma = sp.symbols("k F sigma")
    assert sp.simplify(flow.radial[0] - (-k * R / 2 - F * sp.sin(PHI) / 2)) == 0
    assert sp.simplify(flow.phase[0] - (-sigma + 3 * R**2 / 8 - F * sp.cos(PHI) / (2 * R))) == 0
    assert flow.driven and sigma in flow.parameters and sp.Symbol("w") not in flow.parameters


@pytest.mark.parametrize("text, order, match", [
    ("q'' + q + q**3 = 0", 2, "no small parameter"),
    ("2*q'' + q = eps*q'", 2, "coefficient of q'' is 2"),
    ("q'' + 2*q = eps*q'", 2, "at eps = 0"),
    ("q'' + q = eps*sin(q)*q'", 2, "polynomial"),
    ("q'' + q = eps*q'*cos(t)*q", 2, "parametrically"),
    ("q'' + q = eps*q' + cos(w*t)", 2, "of order eps"),
    ("q'' + q = eps*(q' + cos(w*t) + sin(2*w*t))", 2, "one frequency"),
    ("q'' + q = eps*r*q'", 2, "own variables"),
    (VDP, 0, "orders 1"),
    (VDP, 7, "orders 1"),
])
def test_bad_input_is_one_line(text, order, match):
    with pytest.raises(InputError, match=match) as info:
        slow_flow(oscillator(text), order)
    assert "\n" not in str(info.value)


def test_emitted_right_sides(tmp_path):
    """The compiled slow_flow against lambdify of the same flow, its Jacobian against central
    differences, the Cartesian right side against the polar one (u = r cos φ, v = −r sin φ);
    regenerating gives byte-identical files."""
    from lindstedt.cli import main
    from lindstedt.emit.render import load_generated

    args = ["slowflow", DRIVEN, "--name", "forced", "--param", "k=1/2", "--order", "2",
            "--out", str(tmp_path)]
    assert main(args) == 0
    first = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert sorted(first) == ["forced_slow_flow.py", "forced_slow_flow.tex"]
    assert main(args) == 0
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == first
    m = load_generated(tmp_path / "forced_slow_flow.py")
    assert m.PARAMETERS == ("eps", "F", "sigma")
    flow = slow_flow(oscillator(DRIVEN, {"k": "1/2"}), 2)
    F, sigma = sp.symbols("F sigma")
    ref = sp.lambdify((R, PHI, EPS, F, sigma), flow.rates)
    rng = np.random.default_rng(5)
    for r, phi, eps, f, s in rng.uniform((0.2, -3, 0.01, -1, -2), (3, 3, 0.3, 1, 2), (20, 5)):
        x = np.array([r, phi])
        got = m.slow_flow(x, eps, f, s)
        assert np.allclose(got, ref(r, phi, eps, f, s), rtol=1e-13, atol=1e-15)
        h = 1e-6
        fd = np.column_stack([(m.slow_flow(x + h * e, eps, f, s) - m.slow_flow(x - h * e, eps,
                                                                              f, s)) / (2 * h)
                              for e in np.eye(2)])
        assert np.allclose(m.slow_flow_jacobian(x, eps, f, s), fd, rtol=1e-6, atol=1e-8)
        u, v = r * math.cos(phi), -r * math.sin(phi)
        du, dv = m.slow_flow_cartesian(np.array([u, v]), eps, f, s)
        assert math.isclose((u * du + v * dv) / r, got[0], rel_tol=1e-11, abs_tol=1e-13)
        assert math.isclose((v * du - u * dv) / r**2, got[1], rel_tol=1e-11, abs_tol=1e-13)


def test_cli_json_and_bad_input(capsys):
    import json

    from lindstedt.cli import main

    assert main(["slowflow", "van_der_pol", "--order", "2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["order"] == 2 and data["parameters"] == [] and not data["driven"]
    assert sp.sympify(data["radial"][0], locals={"r": R}) == sp.expand(R / 2 - R**3 / 8)
    assert sp.sympify(data["phase"][1], locals={"r": R}).subs(R, 2) == sp.Rational(-1, 16)
    assert [{k: c[k] for k in ("radius", "averaged_radius", "omega", "stable_for")}
            for c in data["cycles"]] == [{"radius": ["2", "0"], "averaged_radius": ["2", "0"],
                                          "omega": ["1", "0", "-1/16"], "stable_for": "eps > 0"}]
    assert main(["slowflow", "vdp", "--order", "2", "--json"]) == 0  # the registry's alias
    assert json.loads(capsys.readouterr().out) == data
    for bad in (["slowflow", "q'' + q**3 = 0"], ["slowflow", "van_der_pol", "--order", "9"],
                ["slowflow", VDP, "--param", "zz=1"]):
        assert main(bad) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err


@pytest.mark.parametrize("order", [1, 2])
def test_driven_transient(order):
    """The driven Duffing from rest (k = 1/2, F = 1, σ = 1/2; εt ≤ 4): q(t) of the slow flow
    (rotating frame, τ = ωt, mapped back) against DOP853 of the equation with w = 1 + εσ."""
    values = {"k": 0.5, "F": 1.0, "sigma": 0.5}
    flow = slow_flow(oscillator(DRIVEN), order)
    errors = []
    for eps in (0.1, 0.05):
        times = np.linspace(0, 4 / eps, 2001)
        sim = _simulate(DRIVEN, {"k": 0.5, "F": 1.0, "w": 1 + 0.5 * eps}, eps, 0.0, 0.0,
                        times)
        pred = transient(flow, eps, 0.0, 0.0, times, values)
        errors.append(np.max(np.abs(sim - pred)))
    assert 2**order * 0.7 < errors[0] / errors[1] < 2**order * 1.45, errors
