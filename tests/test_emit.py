"""Emission: printers, strict templates, the committed generated/ modules against references."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import commands
import jinja2.meta
import mpmath
import numpy as np
import pytest
import sympy as sp
from lindstedt.analysis.driven import Drive, amplitudes, first_order_branches, harmonic_balance
from lindstedt.cli.demo import DEMO_BALANCE_HARMONICS, DRIVEN_ORDER
from lindstedt.compiler import generate, generate_balance, generate_driven
from lindstedt.derive.cycles import derive_limit_cycle
from lindstedt.derive.lindstedt import (
    derive,
    omega_coefficients,
    period_series,
    solution_expression,
)
from lindstedt.derive.models import (
    A,
    duffing,
    eps,
    oscillator,
    pendulum,
    self_excited_model,
    t,
    theta0,
)
from lindstedt.emit.render import (
    environment,
    render_cycle_derivation,
    render_derivation,
    render_module,
    render_tables,
    template_folder,
)
from lindstedt.emit.render import load_generated as load
from lindstedt.errors import InputError
from lindstedt.lower.documents import (
    lower_cycle_derivation,
    lower_series_derivation,
    lower_tables,
)
from lindstedt.lower.printers import identifier, latex_rational, pycode
from lindstedt.lower.series import lower_periodic
from reference import periodic_orbit
from scipy.special import ellipj, ellipk

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated"
DEFAULTS = [("duffing", 12), ("pendulum", 12)]


@pytest.fixture(scope="module")
def duf():
    return load(GENERATED / "duffing.py")


@pytest.fixture(scope="module")
def pend():
    return load(GENERATED / "pendulum.py")


# --- printers -------------------------------------------------------------------------------

def test_printer_exact_strings():
    x = sp.Symbol("x")
    assert pycode(sp.Rational(3, 8) * x) == "(0.375)*x"
    assert pycode(sp.Rational(1, 3)) == repr(1 / 3)
    assert pycode(sp.cos(x) + 2) == "math.cos(x) + 2"
    assert pycode(sp.Gt(x, -1)) == "(x > -1)"
    assert pycode(x / sp.pi**2) == "x/math.pi**2"
    assert latex_rational(sp.Rational(-21, 256)) == r"-\frac{21}{256}"
    assert r"\begin{array}" in latex_rational(sp.Rational(10**50 + 1, 3))


def _constants(module: Path, *names: str) -> list:
    """The literal values of ``names`` assigned in an emitted module, read without importing
    it (no numba compile)."""
    import ast

    found = {t.id: node.value for node in ast.parse(module.read_text()).body
             if isinstance(node, ast.Assign) for t in node.targets if isinstance(t, ast.Name)}
    return [ast.literal_eval(found[n]) for n in names]


@pytest.mark.parametrize(("k", "a2", "a3"), [("1.3", "0.7", "-2.1"), ("4", "1", "1")])
def test_exact_constants_read_back_as_the_series(tmp_path, k, a2, a3):
    """OMEGA_EXACT and PERIOD_EXACT of ``q'' + k q + ε(a₂q² + a₃q³) = 0`` read back
    (``sympify``) as the series, whether ω₀ = √k multiplies each polynomial coefficient
    (√1.3) or is taken into it (2): Σ ω_k εᵏ and Σ τ_k εᵏ (T/2π) at A = 0.5, ε = 0.01 against
    2π/T and T from the energy integral by mpmath's quadrature (the order-4 truncation
    ~1e-11).  Their text once lost the brackets round a coefficient."""
    made = commands.run("generate", f"q'' + {k}*q + eps*({a2}*q**2 + {a3}*q**3) = 0",
                        "--order", "4", "--out", tmp_path)
    assert made.returncode == 0, made.stderr
    omega, period = _constants(tmp_path / "oscillator.py", "OMEGA_EXACT", "PERIOD_EXACT")
    at = {sp.Symbol("A"): sp.Rational(1, 2)}
    w = sum(sp.sympify(c).subs(at) * sp.Rational(1, 100) ** j for j, c in enumerate(omega))
    T = sum(sp.sympify(c).subs(at) * sp.Rational(1, 100) ** j for j, c in enumerate(period))
    mpmath.mp.dps = 30
    try:
        A, eps = mpmath.mpf("0.5"), mpmath.mpf("0.01")
        K, B, C = (mpmath.mpf(v) for v in (k, a2, a3))
        V = lambda q: K * q**2 / 2 + eps * (B * q**3 / 3 + C * q**4 / 4)  # noqa: E731
        low = mpmath.findroot(lambda q: V(q) - V(A), -A)
        ref = 2 * mpmath.quad(lambda q: 1 / mpmath.sqrt(2 * (V(A) - V(q))), [low, 0, A])
    finally:
        mpmath.mp.dps = 15
    assert abs(float(2 * mpmath.pi * T) / float(ref) - 1) < 1e-10
    assert abs(float(w) * float(ref) / float(2 * mpmath.pi) - 1) < 1e-10
    assert all("*-" not in c for c in (*omega, *period))


@pytest.mark.parametrize("bad", ["import os", "a-b", "class", "__import__", "", "x;y"])
def test_identifiers_are_validated(bad):
    with pytest.raises(InputError):
        identifier(bad)


# --- templates ------------------------------------------------------------------------------

def test_templates_get_exactly_the_variables_they_use(tmp_path, monkeypatch):
    """What the code passes to each template (recorded at render time) against what the
    template's source reads, exactly: module.py.j2, tables.tex.j2 and derivation.tex.j2 (of a
    free oscillator and of a normal mode), the mu_*derivation.tex.j2, slow_flow.tex.j2 and
    cycle_derivation.tex.j2.  Every template is rendered or included."""
    passed: dict[str, list[set]] = {}
    render = jinja2.Template.render

    def record(self, *args, **kwargs):
        passed.setdefault(self.name, []).append(set(dict(*args, **kwargs)))
        return render(self, *args, **kwargs)

    monkeypatch.setattr(jinja2.Template, "render", record)
    sol = derive(duffing(), 5)
    module = lower_periodic(sol, "cmd")
    assert render_module(module).startswith("# Generated by lindstedt")
    render_tables(lower_tables(sol, 3), module.provenance)
    render_derivation(lower_series_derivation(sol, 3), module.provenance)
    generate_driven(1, tmp_path)  # the driven module and mu_derivation.tex.j2
    generate_driven(1, tmp_path, damped=True)  # and mu_damped_derivation.tex.j2
    from lindstedt.compiler import generate_slow_flow

    generate_slow_flow(oscillator("q'' + q = eps*(1 - q**2)*q'"), 2, "cmd", tmp_path)
    render_cycle_derivation(lower_cycle_derivation(derive_limit_cycle(self_excited_model(
        oscillator("q'' + q = eps*(1 - q**2)*q'", name="vdp")), 4), 4), module.provenance)
    from lindstedt.derive.nnm import normal_mode
    from lindstedt.derive.system import parse_system

    mode = normal_mode(parse_system("x1'' + 2*x1 - x2 + x1**3 = 0; x2'' + 2*x2 - x1 = 0"), 1, 4)
    render_tables(lower_tables(mode, 3), module.provenance)
    render_derivation(lower_series_derivation(mode, 3), module.provenance)
    from lindstedt.compiler import generate_ssm

    for text in ("x1'' + x1'/50 + 2*x1 - x2 + x1**3 = f*cos(w*t); x2'' + 2*x2 - x1 = 0",
                 "x1'' + x1'/50 + 2*x1 - x2 + x1**3 = 0; x2'' + 2*x2 - x1 = 0"):
        system = parse_system(text, {"f": "1/100"} if "f" in text else {}, driven=True)
        generate_ssm(system, 1, 3, tmp_path / "ssm", name="reduced", command="cmd",
                     overwrite_edited=True)  # ssm.py.j2 and ssm.tex.j2, driven and not
    folder = template_folder()
    used, includes = {}, {}
    for path in folder.glob("*.j2"):
        ast = environment(path.name.endswith(".tex.j2")).parse(path.read_text())
        used[path.name] = jinja2.meta.find_undeclared_variables(ast)
        includes[path.name] = set(jinja2.meta.find_referenced_templates(ast))
    assert set(passed) | set().union(*includes.values()) == set(used)
    for name, contexts in passed.items():
        reads = used[name].union(*(used[i] for i in includes[name]))
        for ctx in contexts:
            assert reads <= ctx, (name, reads - ctx)  # nothing undefined
    for name in ("module.py.j2", "mu_derivation.tex.j2", "mu_damped_derivation.tex.j2",
                 "slow_flow.tex.j2", "cycle_derivation.tex.j2", "tables.tex.j2",
                 "derivation.tex.j2"):
        assert passed[name] and all(ctx == used[name] for ctx in passed[name]), name
    assert len(passed["tables.tex.j2"]) == len(passed["derivation.tex.j2"]) == 2
    with pytest.raises(jinja2.UndefinedError):
        environment(False).get_template("module.py.j2").render(banner="x")


# --- the generated modules against independent references -----------------------------------

def test_generated_is_fresh(tmp_path):
    """Regenerating the defaults gives byte-identical files (pinned versions, no timestamp)."""
    for model, order in DEFAULTS:
        generate(model, order, tmp_path)
    generate_driven(DRIVEN_ORDER, tmp_path)
    generate_balance(DEMO_BALANCE_HARMONICS, tmp_path)
    fresh = sorted(p.name for p in tmp_path.iterdir())
    committed = sorted(p.name for p in GENERATED.iterdir() if p.is_file())
    assert fresh == committed
    for name in fresh:
        assert (tmp_path / name).read_bytes() == (GENERATED / name).read_bytes(), name


def exact_period_duffing(A_, eps_):
    x = eps_ * A_**2
    m = x / (2 * (1 + x))
    return 4 * ellipk(m) / np.sqrt(1 + x)


def test_duffing_period_within_truncation_error(duf):
    x = np.linspace(-0.6, 0.6, 241)
    A_ = np.full_like(x, 1.7)
    eps_ = x / A_**2
    exact = np.array([float(4 * mpmath.ellipk(xi / (2 * (1 + xi))) / mpmath.sqrt(1 + xi))
                      for xi in x])
    got = duf.period(A_, eps_)
    rel = np.abs(got / exact - 1)
    est = duf.error_estimate(A_, eps_)
    assert np.all(rel <= 2 * est + 4e-16)  # the estimate is honest ...
    assert np.max(rel[np.abs(x) <= 0.3]) < 1e-7  # ... and order 12 is accurate
    assert np.allclose(duf.omega(A_, eps_), 2 * np.pi / exact, rtol=2 * est.max() + 1e-15)


def test_pendulum_period_against_elliptic_integral(pend):
    th = np.linspace(0.0, 2.5, 101)
    exact = 4 * ellipk(np.sin(th / 2) ** 2)
    rel = np.abs(pend.period(th) / exact - 1)
    assert np.all(rel <= 2 * pend.error_estimate(th) + 4e-16)
    assert rel[th <= 1.0].max() < 1e-13


def test_q_against_jacobi_cn(duf):
    """q(t) = A cn(√(1+x) t | m), m = x/(2(1+x)), the exact Duffing solution: within order
    12's truncation, and that truncation is what is seen (halving x divides it by 2¹³)."""
    tt = np.linspace(0, 20, 57)
    A_ = 1.3

    def error(x):
        m = x / (2 * (1 + x))
        if m >= 0:
            exact = A_ * ellipj(np.sqrt(1 + x) * tt, m)[1]
        else:
            exact = np.array([float(mpmath.re(A_ * mpmath.ellipfun("cn", np.sqrt(1 + x) * ti, m)))
                              for ti in tt])
        return np.max(np.abs(duf.q(tt, A_, x / A_**2) - exact))

    for x in (-0.3, 0.1, 0.3):
        err = error(x)
        # order 12 in x, and a phase error ~ t·|δω| growing with time
        assert err <= 20 * A_ * abs(x) ** 13 * (1 + tt.max()), (x, err)
    # the error is x¹³·c(t)(1 + O(x)): log₂ of err(x)/err(x/2) is 13 ± O(x) (12.75 at x = 0.3,
    # 13.37 at −0.3; the O(x) parts cancel in the mean); order 11 or 13 would give 12 or 14
    slopes = [np.log2(error(x) / error(x / 2)) for x in (0.3, -0.3)]
    assert all(12.5 < v < 13.5 for v in slopes) and abs(np.mean(slopes) - 13) < 0.2, slopes


def test_qdot_is_derivative_of_q(duf):
    tt = np.linspace(0.3, 9, 13)
    h = 1e-5
    num = (duf.q(tt + h, 1.1, 0.2) - duf.q(tt - h, 1.1, 0.2)) / (2 * h)
    assert np.allclose(duf.qdot(tt, 1.1, 0.2), num, atol=1e-9)


def test_evaluators_equal_lambdify_of_the_same_expression(duf, pend):
    sol = derive(duffing(), 12)
    omega = sum(c * eps**j for j, c in enumerate(omega_coefficients(sol)))
    f_omega = sp.lambdify((A, eps), omega, "numpy")
    f_period = sp.lambdify((A, eps), period_series(sol), "numpy")
    f_q = sp.lambdify((t, A, eps), solution_expression(sol), "numpy")
    rng = np.random.default_rng(1)
    A_ = rng.uniform(0.2, 2.0, 200)
    x = rng.uniform(-0.9, 0.9, 200)
    e = x / A_**2
    tt = rng.uniform(0, 30, 200)
    np.testing.assert_allclose(duf.omega(A_, e), f_omega(A_, e), rtol=1e-14)
    np.testing.assert_allclose(duf.period(A_, e), f_period(A_, e), rtol=1e-14)
    np.testing.assert_allclose(duf.q(tt, A_, e), f_q(tt, A_, e), rtol=0, atol=1e-13 * A_.max())
    psol = derive(pendulum(12), 12)
    f_pp = sp.lambdify(theta0, period_series(psol), "numpy")
    th = rng.uniform(0, 3, 200)
    np.testing.assert_allclose(pend.period(th), f_pp(th), rtol=1e-14)


def test_nan_outside_the_domain(duf, pend):
    assert np.isnan(duf.period(1.0, -1.0))  # εA² = -1: separatrix, no periodic orbit
    assert np.isnan(duf.omega(2.0, -0.5))  # εA² = -2
    assert np.isnan(duf.q(0.3, 1.0, 1.0))  # |εA²| = 1: outside the radius of convergence
    assert np.isnan(duf.period(np.nan, 0.1))
    assert np.isnan(pend.period(np.pi)) and np.isnan(pend.theta(1.0, 3.5))
    assert np.isfinite(duf.period(1.0, 0.99))


def test_allow_divergent_opt_in(tmp_path):
    generate("duffing", 4, tmp_path, allow_divergent=True)
    mod = load(tmp_path / "duffing.py")
    assert np.isfinite(mod.period(1.0, 3.0))  # divergent sum, explicitly requested
    assert np.isnan(mod.period(1.0, -1.5))  # still no orbit beyond the separatrix
    assert "--allow-divergent" in (tmp_path / "duffing.py").read_text().splitlines()[2]
    # the error estimate is never negative: inf from the radius on (the series bounds nothing
    # there), and inside it bounds the true error (elliptic period), down to the separatrix
    x = np.array([-0.95, -0.5, 0.3, 0.9, 0.999, 1.0, 1.5, 3.0, 1e4])
    est = mod.error_estimate(1.0, x)
    inside = np.abs(x) < 1
    assert np.all(np.isinf(est[~inside])) and np.all(est[inside] > 0)
    exact = 4 * ellipk(x[inside] / (2 * (1 + x[inside]))) / np.sqrt(1 + x[inside])
    rel = np.abs(mod.period(1.0, x[inside]) / exact - 1)
    assert np.all(rel <= 3 * est[inside]), (rel, est[inside])
    out = np.empty(x.size)
    mod.error_estimate_into(out, np.ones(x.size), x)
    assert np.allclose(out, est, rtol=1e-13)  # inf equals inf


def test_broadcasting(duf, pend):
    tt = np.linspace(0, 1, 5)[:, None]
    A_ = np.linspace(0.1, 1, 3)[None, :]
    assert duf.q(tt, A_, 0.1).shape == (5, 3)
    assert duf.period(A_, 0.2).shape == (1, 3)
    assert isinstance(float(duf.omega(1.0, 0.1)), float)
    assert pend.theta(tt, 0.5).shape == (5, 1)


def _same(a: np.ndarray, b: np.ndarray) -> None:
    """NaN at the same places, within 2 ulp elsewhere (LLVM may order the additions of a
    polynomial's Estrin split differently in the vectorised loop: emit.FASTMATH)."""
    assert np.array_equal(np.isnan(a), np.isnan(b))
    np.testing.assert_array_max_ulp(a[~np.isnan(a)], b[~np.isnan(b)], maxulp=2)


def test_into_twins_equal_the_ufuncs(duf, pend):
    """``<name>_into(out, …)``: scalars and 1-D arrays mixed, the ufunc's values and NaNs;
    its vectorised cos/sin within 2 ulp of libm's, phases beyond 2**20 through libm."""
    t = np.concatenate([np.linspace(0, 30, 95), [1e5, 9e5, 2e6, 1e8, 1e12, -3e6]])
    eps = np.linspace(-1.2, 1.2, 101)  # beyond both ends of the domain: NaN in both
    for args in ((t, 0.7, 0.2), (t, 0.7, eps), (1.5, np.full(101, 0.7), eps)):
        np.testing.assert_allclose(duf.q_into(np.empty(101), *args), duf.q(*args), rtol=0,
                                   atol=4e-16)
        np.testing.assert_allclose(duf.qdot_into(np.empty(101), *args), duf.qdot(*args),
                                   rtol=0, atol=4e-16)
    x = np.random.default_rng(11).uniform(-1e6, 1e6, 10**5)  # the phase alone: q with ε = 0
    np.testing.assert_allclose(duf.q_into(np.empty_like(x), x, 1.0, 0.0), np.cos(x), rtol=0,
                               atol=2.3e-16)
    _same(duf.period_into(np.empty(101), 1.0, eps), duf.period(1.0, eps))
    th = np.linspace(0, 3.5, 101)
    _same(pend.period_into(np.empty(101), th), pend.period(th))
    with pytest.raises(ValueError, match="out's length"):
        duf.period_into(np.empty(3), 1.0, eps)


def test_cached_module_imports_without_recompiling(tmp_path):
    shutil.copy(GENERATED / "duffing.py", tmp_path / "duffing.py")
    code = "import duffing; duffing.q(1.0, 1.0, 0.1); duffing.period(1.0, 0.1)"
    env = {**os.environ, "NUMBA_DEBUG_CACHE": "1", "PYTHONPATH": str(tmp_path)}
    first = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    second = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert first.returncode == 0 and second.returncode == 0, second.stderr
    assert "data saved" in first.stdout
    assert "data loaded" in second.stdout and "data saved" not in second.stdout


SCALED_DRIVES = [(3.0, 1.0, 3.0), (-1.9, -0.5, 2.0), (6.0, 1.0, 1.0)]
# NOTE: (ω² − 1, ε, f) = λ·(s, e, g): the right side of the μ-equation is then O(λ) while the
# branches (roots A of sA − ¾eA³ + g = 0) do not move, so order K is off the true orbit by
# O(λ^{K+1}).  The third drive has three branches.


def test_driven_module_against_the_true_orbit():
    """The emitted A_n (n = 1, 3, 5, 7) on every branch against the periodic orbit found by
    DOP853 and Newton's method on the period map (tests/reference.py, not the package), from
    the cubic's roots (numpy.roots, largest first): off by order ORDER's truncation
    O(λ^{ORDER+1}), and by exactly that (halving λ divides it by 2^{ORDER+1})."""
    drv = load(GENERATED / "driven.py")
    K = drv.ORDER
    for s, e, g in SCALED_DRIVES:
        roots = np.roots([-0.75 * e, 0.0, s, g])
        branches = sorted((r.real for r in roots if abs(r.imag) < 1e-9), reverse=True)
        errors = []
        for lam in (0.02, 0.01):
            w, eps_, f = np.sqrt(1 + lam * s), lam * e, lam * g
            row = []
            for k, a in enumerate(branches):
                assert drv.first_order(w, eps_, f, k) == pytest.approx(a, rel=1e-12, abs=1e-14)
                A, B = periodic_orbit(eps_, f, w, a)
                assert np.max(np.abs(B[:16])) < 1e-10 and np.max(np.abs(A[2:16:2])) < 1e-10
                err = max(abs(getattr(drv, f"A_{n}")(w, eps_, f, k) - A[n]) for n in (1, 3, 5, 7))
                assert err <= 0.5 * lam ** (K + 1), (s, e, g, lam, k, err)
                row.append(err)
            assert np.isnan(drv.A_1(w, eps_, f, len(branches)))  # no such branch
            errors.append(row)
        for k, (coarse, fine) in enumerate(zip(*errors, strict=True)):
            if coarse > 1e-10:  # above the reference's own error (the middle branch is not)
                assert 2 ** (K + 0.5) < coarse / fine < 2 ** (K + 1.5), (s, e, g, k, coarse, fine)
    with np.errstate(divide="ignore", invalid="ignore"):
        assert np.isnan(drv.A_1(1.0, 0.0, 1.0, 0))  # ε = 0: not a Duffing oscillator


def test_driven_module_at_the_linear_resonance():
    """ω = 1 (λ = 0.01 of the notes' ε = 0.1, f = 1): order 3 is 1.6e-9 off the true orbit.
    (Cardano's root in its naive form cancelled here: A₁ was 1e-5 off, ~(ulp)^(1/3).)"""
    drv = load(GENERATED / "driven.py")
    eps_, f, w = 0.01, 0.1, 1.0
    a = max(r.real for r in np.roots([-0.75 * eps_, 0.0, 0.0, f]) if abs(r.imag) < 1e-9)
    A, _ = periodic_orbit(eps_, f, w, a)
    assert abs(drv.first_order(w, eps_, f, 0) - a) <= 1e-12
    assert abs(drv.A_1(w, eps_, f, 0) - A[1]) <= 1e-8


@pytest.mark.parametrize("w", [1.5, 3.0, 10.0])
@pytest.mark.parametrize("eps_", [1e-20, 1e-12, 1e-4])
def test_driven_module_middle_root_at_a_tiny_eps(w, eps_):
    """The middle root of (ω² − 1)A − ¾εA³ + f = 0 tends to f/(1 − ω²) as ε → 0 while the
    others run off like 1/√ε: the trigonometric formula's cosine passes through zero there and
    kept only ~√ε of the digits (1e-5 off at ε = 1e-20, differently in the ufunc and in its
    SIMD loop).  Against mpmath's root at 40 digits, in the ufunc and in A_1_into."""
    drv = load(GENERATED / "driven.py")
    f = 2.0
    with mpmath.workdps(40):
        root = mpmath.findroot(lambda a: (w * w - 1) * a - 0.75 * mpmath.mpf(eps_) * a**3 + f,
                               f / (1 - w * w))
    assert drv.first_order(w, eps_, f, 1) == pytest.approx(float(root), rel=1e-13)
    # the μ-expansion's corrections are O(ε): A_1 is the root to that
    omegas = np.full(7, w)
    got = drv.A_1_into(np.empty(7), omegas, eps_, f, 1.0)
    assert np.all(np.abs(got / float(root) - 1) <= max(1e-13, 10 * eps_))
    assert drv.A_1(w, eps_, f, 1) == pytest.approx(float(root), rel=max(1e-13, 10 * eps_))


def test_balance_module_newton_equals_convolution_balance():
    """The emitted residual/Jacobian (SymPy product-to-sum) against the convolution route."""
    bal = load(GENERATED / "balance.py")
    n = bal.HARMONICS
    d = Drive(0.1, 0.3, 1.3, Q=20.0)
    for br in first_order_branches(d):
        x0 = np.zeros(2 * n)
        x0[0], x0[n] = br.A1 * np.cos(br.delta0), br.A1 * np.sin(br.delta0)
        x, ok = bal.newton(x0, d.omega, d.eps, d.force, d.damping)
        hb = harmonic_balance(d, br, n)
        A, B = amplitudes(hb.coefficients, 0.0, 2 * n - 1)
        assert ok
        np.testing.assert_allclose(x, [*A.values(), *B.values()], atol=1e-12)
        # Jacobian against central differences of the residual
        h = 1e-6
        num = np.column_stack([
            (bal.residual(x + h * e, 1.3, 0.1, 0.3, 0.05) - bal.residual(x - h * e, 1.3, 0.1, 0.3,
                                                                        0.05)) / (2 * h)
            for e in np.eye(2 * n)])
        np.testing.assert_allclose(bal.jacobian(x, 1.3, 0.1, 0.3, 0.05), num, atol=1e-7)


def test_driven_module_refuses_near_a_fold():
    drv = load(GENERATED / "driven.py")
    eps_, f = 0.1, 1.0
    A = -((2 * f) / (3 * eps_)) ** (1 / 3)
    w = np.sqrt(1 + 2.25 * eps_ * A**2)
    w = w * (1 + 1e-9)  # three branches exist, two of them about to merge
    assert all(np.isfinite(drv.first_order(w, eps_, f, k)) for k in range(3))
    values = [drv.A_1(w, eps_, f, k) for k in range(3)]
    assert np.isfinite(values[0]) and np.isnan(values[1:]).any()


# --- files: atomic, no clobbering, bad input -------------------------------------------------

def test_refuses_to_overwrite_foreign_file(tmp_path):
    (tmp_path / "duffing.py").write_text("my own work\n")
    with pytest.raises(InputError, match="not written by lindstedt"):
        generate("duffing", 3, tmp_path)
    assert (tmp_path / "duffing.py").read_text() == "my own work\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["duffing.py"]  # nothing else written


def run_cli(*args):
    return commands.run(*args)


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_unwritable_out_non_root(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    out = run_cli("generate", "duffing", "--order", "3", "--out", str(ro))
    assert out.returncode == 2 and "not writable" in out.stderr


def test_out_is_a_file(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    out = run_cli("generate", "duffing", "--order", "3", "--out", str(f))
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1
    assert f.read_text() == "x"


def test_out_cannot_be_created():
    out = run_cli("generate", "duffing", "--order", "3", "--out", "/proc/lindstedt-nope")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_generate_bad_order_and_model(tmp_path):
    for args in (["duffing", "--order", "-2"], ["nosuch"]):
        out = run_cli("generate", *args, "--out", str(tmp_path / "o"))
        assert out.returncode == 2 and "Traceback" not in out.stderr
    assert not (tmp_path / "o").exists()
