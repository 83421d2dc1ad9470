"""Transition curves of Hill's equation x'' + (δ + ε p(t))x = 0 and the damped tongue's tip:
against Floquet multipliers (compiled RK4 and SciPy's solve_ivp), the truncated Hill matrix
(mpmath), Mathieu's a_m, b_m (DLMF 28.6) and the ODE itself."""

from __future__ import annotations

import json
import math
from fractions import Fraction as F

import mpmath as mp
import numpy as np
import pytest
from commands import run
from lindstedt.cli import main
from lindstedt.derive.hill import fourier_of_text, mathieu_series, tongue_tip, transition_curves
from lindstedt.errors import InputError
from lindstedt.numerics.floquet import floquet_stable, floquet_traces
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar


def value(coefficients, x: float) -> float:
    return sum(float(c) * x**k for k, c in enumerate(coefficients))


def harmonics(text: str) -> dict[int, tuple[float, float]]:
    return {k: (float(a), float(b)) for k, (a, b) in fourier_of_text(text).items()}


DLMF_28_6 = {  # 28.6.1–28.6.5: coefficients of q^0 … q^8 (a_1, b_1 to q^6)
    ("a", 0): [0, 0, F(-1, 2), 0, F(7, 128), 0, F(-29, 2304), 0, F(68687, 18874368)],
    ("a", 1): [1, 1, F(-1, 8), F(-1, 64), F(-1, 1536), F(11, 36864), F(49, 589824)],
    ("b", 1): [1, -1, F(-1, 8), F(1, 64), F(-1, 1536), F(-11, 36864), F(49, 589824)],
    ("a", 2): [4, 0, F(5, 12), 0, F(-763, 13824), 0, F(1002401, 79626240), 0,
               F(-1669068401, 458647142400)],
    ("b", 2): [4, 0, F(-1, 12), 0, F(5, 13824), 0, F(-289, 79626240), 0,
               F(21391, 458647142400)],
}


@pytest.mark.parametrize("n", range(3))
def test_mathieu_is_the_named_case(n):
    """p = cos t: δ = a/4 with q = −2ε (y'' + (a − 2q cos 2z)y = 0 with z = t/2): the cos
    curve is a_n, the sin curve b_n, coefficient by coefficient against DLMF 28.6."""
    tongue = transition_curves("cos(t)", n, 8)
    kinds = ["a"] if n == 0 else ["a", "b"]
    assert len(tongue.curves) == len(kinds)
    for kind, curve in zip(kinds, tongue.curves, strict=True):
        expected = DLMF_28_6[(kind, n)]
        assert [4 * d * F(-1, 2) ** k for k, d in enumerate(curve.delta)][:len(expected)] \
            == expected, (kind, n)
    for m in range(6):  # and mathieu_series is this named case
        assert mathieu_series("a", m, 10) == [4 * d * F(-1, 2) ** k for k, d in
                                              enumerate(transition_curves("cos(t)", m, 10)
                                                        .curves[0].delta)]


def hill_matrix_values(text: str, n: int, eps: float, size: int = 21) -> list[mp.mpf]:
    """The two (one for n = 0) eigenvalues α/4 next to n²/4 of the truncated Hill matrix of
    ``x'' + (α + εP(τ))x = 0`` on ``e^{ijτ}``, ``j ≡ n (mod 2)``, ``P = 4p(2τ)``."""
    p = fourier_of_text(text)
    hat = {}  # P = Σ hat[m] e^{imτ}: cos kt = cos 2kτ -> ±2k with 1/2 each
    for k, (a, b) in p.items():
        a, b = mp.mpf(a.numerator) / a.denominator, mp.mpf(b.numerator) / b.denominator
        for m, c in ((2 * k, (a - 1j * b) / 2), (-2 * k, (a + 1j * b) / 2)):
            hat[m] = hat.get(m, 0) + 4 * (c if k else a)
    js = [n % 2 + 2 * (i - size // 2) for i in range(size)]
    H = mp.matrix(size, size)
    for r, j in enumerate(js):
        for c, jj in enumerate(js):
            H[r, c] = (j * j if r == c else 0) - eps * hat.get(j - jj, 0)
    values = sorted(mp.re(v) / 4 for v in mp.eighe(H, eigvals_only=True))
    near = sorted(values, key=lambda v: abs(v - mp.mpf(n * n) / 4))[: 1 if n == 0 else 2]
    return sorted(near)


@pytest.mark.parametrize(("text", "n"), [("cos(t) + 1/2*cos(2*t)", 1),
                                         ("cos(t) + 1/2*cos(2*t)", 2),
                                         ("cos(t) + 1/2*cos(2*t)", 0),
                                         ("cos(t) + sin(2*t)", 1), ("cos(t) + sin(2*t)", 2),
                                         ("3*cos(t) + 4*sin(t)", 1), ("sin(t)", 3)])
def test_two_harmonics_against_the_hill_matrix(text, n):
    tongue = transition_curves(text, n, 20)
    eps = 0.05
    with mp.workdps(30):
        expected = hill_matrix_values(text, n, eps)
    got = sorted(value(c.delta, eps) for c in tongue.curves)
    assert len(got) == len(expected)
    for g, e in zip(got, expected, strict=True):
        assert abs(g - float(e)) < 1e-13, (text, n, got, expected)


@pytest.mark.parametrize(("text", "n"), [("cos(t) + 1/2*cos(2*t)", 1),
                                         ("cos(t) + 1/2*cos(2*t)", 2),
                                         ("cos(t) + sin(2*t)", 2), ("cos(t)", 3)])
def test_the_curves_are_the_floquet_boundary(text, n):
    """|tr M| = 2 on each curve: the numerical boundary (compiled RK4, 4096 steps) crosses
    the series curve within 1e-9 in δ at ε = 0.1 (the order-24 truncation is far below)."""
    p = harmonics(text)
    eps = 0.1
    for curve in transition_curves(text, n, 24).curves:
        d = value(curve.delta, eps)
        gap = 2e-4 if n < 3 else 2e-6  # the curves of tongue 3 split at ε³ only

        def margin(delta):
            tr, _ = floquet_traces(delta, eps, p, steps=4096)
            return abs(float(tr)) - 2

        assert margin(d - gap) * margin(d + gap) < 0, (text, n, curve.label)
        assert abs(brentq(margin, d - gap, d + gap, xtol=1e-14) - d) < 1e-9, curve.label


def test_the_periodic_solution_solves_the_equation():
    """x = Σ ε^k x_k on the curve: the residual of x'' + (α + εP)x in τ = t/2 is O(ε^(K+1))."""
    eps, order = 0.05, 16
    for text, n in (("cos(t) + 1/2*cos(2*t)", 1), ("cos(t) + sin(2*t)", 2)):
        tongue = transition_curves(text, n, order)
        p = fourier_of_text(text)
        tau = np.linspace(0, 2 * np.pi, 101)
        P = 4 * sum(float(a) * np.cos(2 * k * tau) + float(b) * np.sin(2 * k * tau)
                    for k, (a, b) in p.items())
        for curve in tongue.curves:
            x, x2 = np.zeros_like(tau), np.zeros_like(tau)
            for k, modes in enumerate(curve.solution):
                for (kind, j), c in modes.items():
                    f = (np.cos if kind == 0 else np.sin)(j * tau) * float(c) * eps**k
                    x += f
                    x2 -= j * j * f
            alpha = 4 * value(curve.delta, eps)
            assert np.max(np.abs(x2 + (alpha + eps * P) * x)) < 1e-15 * 10 ** (order // 2)


def test_the_damped_tongue_tip_against_floquet():
    """ε_min(ζ) of ẍ + 2ζẋ + (δ + ε cos t)x = 0 at tongue 1: the lowest ε where some δ has a
    multiplier outside the unit circle (RK4 monodromy, minimised over δ, bisected in ε)."""
    tip = tongue_tip("cos(t)", 1, 12)
    assert tip.eps_min[:4] == (0, 2, 0, F(3, 2))  # ε_min = 2ζ + 3ζ³/2 + …
    assert tongue_tip("cos(t)", 1, 0).eps_min == (0,) and len(tip.delta) == 13
    p = {1: (1.0, 0.0)}
    zeta = 0.05
    bound = 1 + math.exp(-4 * math.pi * zeta)

    def worst(eps):
        r = minimize_scalar(lambda d: -abs(float(floquet_traces(d, eps, p, zeta, 2048)[0])),
                            bounds=(0.2, 0.27), method="bounded", options={"xatol": 1e-10})
        return -r.fun - bound

    eps_min = brentq(worst, 0.05, 0.2, xtol=1e-13)
    assert abs(eps_min - value(tip.eps_min, zeta)) < 1e-10
    assert abs(value(tip.eps_min, zeta) - 2 * zeta) > 1e-4  # the correction is resolved


def monodromy_scipy(delta, eps, zeta):
    def rhs(t, y):
        k = delta + eps * np.cos(t)
        return [y[1], -2 * zeta * y[1] - k * y[0], y[3], -2 * zeta * y[3] - k * y[2]]
    sol = solve_ivp(rhs, (0, 2 * np.pi), [1, 0, 0, 1], method="DOP853", rtol=1e-12,
                    atol=1e-13)
    return np.array([[sol.y[0, -1], sol.y[2, -1]], [sol.y[1, -1], sol.y[3, -1]]])


@pytest.mark.parametrize("zeta", [0.0, 0.05])
def test_grid_verdicts_against_solve_ivp(zeta):
    delta = np.array([0.1, 0.25, 0.6, 1.0, 1.5, 2.25, -0.2])
    eps = np.array([0.5, 0.3, 0.4, 0.8, 0.2, 1.0, 0.3])
    tr, det = floquet_traces(delta, eps, {1: (1.0, 0.0)}, zeta)
    stable = floquet_stable(tr, zeta)
    for i in range(delta.size):
        M = monodromy_scipy(delta[i], eps[i], zeta)
        assert abs(tr[i] - np.trace(M)) < 1e-5 and abs(det[i] - np.linalg.det(M)) < 1e-6
        assert stable[i] == bool(np.all(np.abs(np.linalg.eigvals(M)) < 1 + 1e-12 * (zeta == 0)
                                        ) if zeta else abs(np.trace(M)) < 2)
    assert not stable.all() and stable.any()


def test_the_cli_json():
    out = run("tongues", "cos(t) + sin(2*t)", "--n", "2", "--order", "6", "--json", "--eps", "0.1")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["variable"] == "eps" and data["delta0"] == "1/1" and data["period"] == "2*pi"
    assert len(data["curves"]) == 2 and all(len(c["series"]) == 7 for c in data["curves"])
    assert data["curves"][0]["series"][0] == "1/1"
    assert [c["label"] for c in data["curves"]] == ["lower (1*cos(t) + 1*sin(t))",
                                                    "upper (1*cos(t) - 1*sin(t))"]
    assert data["curves"][0]["solution"][0] and "at" in data["curves"][0]


@pytest.mark.parametrize("args", [
    ["cos(sqrt(2)*t)"], ["t*cos(t)"], ["cos(t/2)"], ["a*cos(t)"], ["exp(t)"], ["1"],
    ["sqrt(2)*cos(t)"], ["cos(t)", "--n", "1.5"], ["cos(t)", "--n", "-1"],
    ["cos(t)", "--zeta", "nan"], ["cos(t)", "--eps", "inf"],
    ["cos(t)", "--order", "20", "--eps", "1.5", "--tol", "1e-30"],
    ["cos(t) + sin(t)", "--n", "1"], ["cos(t) + sin(2*t)", "--n", "3"],
    ["cos(t)", "--n", "2", "--zeta", "0.1"], ["cos(t)", "--n", "0", "--zeta", "0.1"],
    ["cos(t)", "--tol", "1e-3"], ["cos(t)", "--plot", "chart.txt"],
])
def test_bad_input_is_one_line_and_exit_2(args):
    done = run("tongues", *args)
    assert done.returncode == 2 and done.stdout == "", args
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("lindstedt: error:"), args


def test_the_tolerance_refusal_names_the_best_reachable(capsys):
    assert main(["tongues", "cos(t)", "--order", "20", "--eps", "1.5", "--tol", "1e-30"]) == 2
    assert "best reachable" in capsys.readouterr().err
    with pytest.raises(InputError, match="not periodic"):
        transition_curves("cos(sqrt(2)*t)", 1, 4)


def test_the_chart_is_reproducible(tmp_path):
    from lindstedt.charts import ince_strutt_figure

    first = ince_strutt_figure(tmp_path / "a.png", grid=40, order=12).read_bytes()
    again = ince_strutt_figure(tmp_path / "a.png", grid=40, order=12).read_bytes()
    assert first == again and first.startswith(b"\x89PNG")
    with pytest.raises(InputError):
        ince_strutt_figure(tmp_path / "a.txt", grid=40)


def test_the_curves_radius_is_mathieus(capsys):
    """Tongue 1 of p = cos t is a_1, b_1 at q = −2ε: its radius in ε is ρ⁽³⁾₀/2 (DLMF Table
    28.6.1: 3.7699574940), within 0.1 % from order 100."""
    assert main(["tongues", "cos(t)", "--n", "1", "--order", "100", "--singularities",
                 "--json"]) == 0
    for curve in json.loads(capsys.readouterr().out)["curves"]:
        (row,) = curve["singularities"]
        assert row["variable"] == "eps" and abs(row["radius"] / (3.7699574940 / 2) - 1) < 1e-3


EMIT_P = "cos(t) + 1/2*cos(2*t)"
EMIT_ARGS = ["tongues", EMIT_P, "--n", "1", "--order", "30", "--out"]


@pytest.fixture(scope="module")
def emitted(tmp_path_factory):
    """``tongues P --n 1 --order 30 --out DIR``, twice into two folders, and the module."""
    from lindstedt.emit.render import load_generated

    first, again = tmp_path_factory.mktemp("tongue"), tmp_path_factory.mktemp("again")
    assert main([*EMIT_ARGS, str(first)]) == 0 and main([*EMIT_ARGS, str(again)]) == 0
    return first, again, load_generated(first / "tongue_1.py")


def boundary(p, eps: float, near: float) -> float:
    """|tr M| = 2 by brentq next to ``near`` (compiled RK4 at 8192 steps: ~1e-13 in δ)."""
    def margin(delta):
        return abs(float(floquet_traces(delta, eps, p, steps=8192)[0])) - 2

    return brentq(margin, near - 1e-6, near + 1e-6, xtol=1e-15)


def test_the_emitted_curves_are_the_floquet_boundary_past_the_radius(emitted):
    """delta_0, delta_1 against brentq on |tr M| − 2 between and at the verified grid points,
    to 2e-10; curve 0 past its radius (~1.33), where the partial sum is off by > 1e-3."""
    _, _, mod = emitted
    p = harmonics(EMIT_P)
    tongue = transition_curves(EMIT_P, 1, 30)
    assert mod.LIMIT_0 > 2.0 and mod.LIMIT_1 > 1.5
    assert len(tongue.curves) == 2
    for i in range(2):
        f, limit = getattr(mod, f"delta_{i}"), getattr(mod, f"LIMIT_{i}")
        for eps in (0.3, 1.0, 1.5, limit):
            got = float(f(eps))
            assert abs(got - boundary(p, eps, got)) < 2e-10, (i, eps)
            assert 0 <= float(getattr(mod, f"delta_{i}_error")(eps)) < 1e-8, (i, eps)
    got = float(mod.delta_0(2.0))
    truth = boundary(p, 2.0, got)
    assert abs(value(tongue.curves[0].delta, 2.0) - truth) > 1e-3  # the series is useless here
    assert abs(got - truth) < 2e-10


def test_the_emitted_curves_hold_the_tolerance_between_the_grid_points(emitted):
    """Points of (0, LIMIT_i] off the verification grid (fractions of the limit that are no
    multiple of its spacing), just below the limit included: within the module's TOLERANCE
    (1e-10) of the boundary found by brentq at 8192 steps."""
    _, _, mod = emitted
    p = harmonics(EMIT_P)
    assert mod.TOLERANCE == 1e-10
    for i in range(2):
        f, limit = getattr(mod, f"delta_{i}"), getattr(mod, f"LIMIT_{i}")
        for eps in limit * np.array([0.1234567, 0.5011, 0.7777, 0.9123, 0.9871, 0.9993]):
            got = float(f(eps))
            assert abs(got - boundary(p, eps, got)) < mod.TOLERANCE, (i, eps)


def test_the_bracketed_root_is_brentqs():
    """methods.boundary_bracket (the sign of |tr M| − 2 at δ ∓ b, the root interpolated):
    brentq's root where one curve crosses the bracket, NaN where none or both do."""
    from lindstedt.methods.verify import boundary_bracket

    p = harmonics(EMIT_P)
    curves = transition_curves(EMIT_P, 1, 30).curves
    first = boundary(p, 0.3, value(curves[0].delta, 0.3))
    d0, d1 = (boundary(p, 1.0, value(c.delta, 1.0)) for c in curves)
    eps = np.array([0.3, 1.0, 1.0, 1.0])
    near = np.array([first + 4e-11, d1 - 7e-11, d0 + 3e-10, (d0 + d1) / 2])
    bracket = np.array([1e-10, 1e-10, 1e-10, abs(d1 - d0) / 2 + 0.01])
    got = boundary_bracket(p, eps, near, bracket, 8192)
    assert abs(got[0] - first) < 1e-14 and abs(got[1] - d1) < 1e-14, got
    assert np.isnan(got[2]) and np.isnan(got[3])  # outside the bracket; both curves inside


def test_the_emitted_curves_are_nan_beyond_the_verified_eps(emitted):
    _, _, mod = emitted
    outside = np.array([-0.1, mod.LIMIT_0 * 1.001, 50.0, np.nan, np.inf, -np.inf, 1e308])
    with np.errstate(all="raise"):
        for name in ("delta_0", "delta_1", "delta_0_error", "delta_1_error"):
            assert np.isnan(getattr(mod, name)(outside)).all(), name
    assert math.isnan(mod.delta_1(mod.LIMIT_1 * 1.001)) and math.isfinite(mod.delta_1(0.0))


def test_the_emitted_module_is_byte_identical_on_rerun(emitted):
    first, again, _ = emitted
    text = (first / "tongue_1.py").read_bytes()
    assert text == (again / "tongue_1.py").read_bytes()
    assert b"cos(t) + 1/2*cos(2*t)" in text and b"def delta_1_error(eps)" in text


def test_emit_refuses_in_one_line(tmp_path):
    """A foreign file in the way, a bad P, a too low order: exit 2, one line, nothing written."""
    (tmp_path / "tongue_1.py").write_text("mine\n")
    for args in ([*EMIT_ARGS, str(tmp_path)],
                 ["tongues", "cos(sqrt(2)*t)", "--out", str(tmp_path / "new")],
                 ["tongues", "cos(t)", "--order", "8", "--out", str(tmp_path / "new")],
                 ["tongues", "cos(t)", "--out", " "],
                 ["tongues", "cos(t)", "--eps", "0.1", "--out", str(tmp_path / "new")]):
        done = run(*args)
        assert done.returncode == 2 and done.stdout == "", args
        assert done.stderr.count("\n") == 1 and done.stderr.startswith("lindstedt: error:"), \
            (args, done.stderr)
    assert (tmp_path / "tongue_1.py").read_text() == "mine\n"
    assert not (tmp_path / "new").exists()


def test_an_even_curve_is_emitted_in_eps_squared(tmp_path):
    """p = cos t, n = 0 (a_0(−2ε)/4, even in ε): Padé in ε², NaN only for |ε| beyond the
    limit, and equal to the Floquet boundary at ±ε past the radius of a_0 (|q| ≈ 1.4688)."""
    from lindstedt.emit.render import load_generated

    assert main(["tongues", "cos(t)", "--n", "0", "--order", "30", "--out", str(tmp_path)]) == 0
    mod = load_generated(tmp_path / "tongue_0.py")
    assert mod.SYMMETRIC_0 and mod.LIMIT_0 > 1.4688 / 2
    eps = 0.99 * mod.LIMIT_0
    got = float(mod.delta_0(-eps))
    assert got == float(mod.delta_0(eps))
    assert abs(got - boundary({1: (1.0, 0.0)}, -eps, got)) < 2e-10
    assert math.isnan(mod.delta_0(-1.01 * mod.LIMIT_0)) and not hasattr(mod, "delta_1")
