"""The emitted normal-mode module: its ufuncs against the exact series and against shooting,
NaN beyond the radius, the ``_into`` twins, and bad input for ``generate SYSTEM``."""

from __future__ import annotations

import functools
import importlib.util
import math

import mpmath
import numpy as np
import pytest
import sympy as sp
from commands import run
from lindstedt.derive.nnm import normal_mode
from lindstedt.derive.system import parse_system
from test_nnm import KERSCHEN, _evaluate, _shoot


@pytest.fixture(scope="module")
def mode2(tmp_path_factory):
    out = tmp_path_factory.mktemp("nnm")
    done = run("generate", KERSCHEN, "--mode", "2", "--order", "12", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == [str(out / "mode2.py"), str(out / "mode2_derivation.tex"),
                                   str(out / "mode2_tables.tex")]
    spec = importlib.util.spec_from_file_location("mode2", out / "mode2.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_backbone_and_shape_match_shooting(mode2):
    for A, tol in ((0.1, 1e-8), (0.3, 1e-5)):
        series = normal_mode(parse_system(KERSCHEN), 2, 12)
        period, starts = _evaluate(series, A)
        others, shot = _shoot(KERSCHEN, A, starts[1:], period / 2)
        assert abs(mode2.period(A) / shot - 1) <= tol
        assert abs(mode2.omega(A) * shot / (2 * np.pi) - 1) <= tol
        assert mode2.x1(0.0, A) == pytest.approx(A, rel=1e-15)
        assert abs(mode2.x2(0.0, A) - others[0]) / A <= tol
        # half a period on, every coordinate is at its other turning point
        assert mode2.x1(shot / 2, A) == pytest.approx(-A, abs=tol * A * 10)


def test_ufuncs_and_into_twins_agree_and_refuse_past_the_radius(mode2):
    A = np.linspace(-0.5, 0.5, 101)
    out = np.empty_like(A)
    mode2.omega_into(out, A)
    np.testing.assert_allclose(out, mode2.omega(A), rtol=1e-15, atol=0)  # FMA may differ
    t = np.linspace(0, 10, 101)
    mode2.x2_into(out, t, 0.3)
    np.testing.assert_allclose(out, mode2.x2(t, 0.3), rtol=0, atol=1e-15)
    beyond = np.sqrt(mode2.RADIUS) * 1.01  # y = A² beyond the radius in y
    assert np.isnan(mode2.omega(beyond)) and np.isnan(mode2.x1(1.0, beyond))
    assert np.isnan(mode2.omega(np.nan)) and np.isnan(mode2.x1(np.inf, 0.1))
    assert mode2.OMEGA0_EXACT == "sqrt(3)" and mode2.MODE == 2


@pytest.mark.parametrize("args, says", [
    (["--mode", "3"], "--mode 3: the system has modes 1..2"),
    (["--damped"], "--damped: not for a system's normal mode"),
    (["--amplitude", "x9"], "--amplitude x9: not a coordinate"),
    (["--name", "numpy"], "name 'numpy': a module of that name is importable"),
])
def test_generate_system_refusals_write_nothing(tmp_path, args, says):
    out = run("generate", KERSCHEN, *args, "--out", str(tmp_path / "new"))
    assert out.returncode == 2 and out.stdout == ""
    assert len(out.stderr.strip().splitlines()) == 1 and says in out.stderr, out.stderr
    assert not (tmp_path / "new").exists()


def test_mode_flag_without_a_system_is_refused():
    out = run("generate", "duffing", "--mode", "2", "--out", "x")
    assert out.returncode == 2 and "a system's flags" in out.stderr


MEMS = "x1'' + x1 + 0.5*(x1-x2) + 0.3*x1**3 = 0; x2'' + 1.21*x2 + 0.5*(x2-x1) = 0"
# NOTE: ω0² = (321 ∓ √10441)/200: the coefficients live in Q(√10441), and the ratios of
# mode 1's ω_j swing (3.3 … 19 over the first orders), so its radius estimate spreads wide.


def _load(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@functools.cache
def _mems_series(which: int):
    return normal_mode(parse_system(MEMS), which, 24)  # as generate derives it (radius)


@pytest.fixture(scope="module")
def mems1(tmp_path_factory):
    """Mode 1's order-8 module, the one whose guard was ``if not (False)``: NaN everywhere."""
    from lindstedt.emit.render import render_module
    from lindstedt.lower.series import lower_periodic

    path = tmp_path_factory.mktemp("mems") / "mems1.py"
    path.write_text(render_module(lower_periodic(_mems_series(1), "test", 8, "mems1")))
    return _load(path, "mems1")


def _shot_period(which: int, A: float) -> float:
    series = _mems_series(which)
    period, starts = _evaluate(series, A)
    return _shoot(MEMS, A, starts[1:], period / 2)[1]


def test_mems_mode_1_module_meets_shooting_with_a_real_positive_radius_bound(mems1):
    """The order-8 module of a pair in Q(√10441): ω within 1e-8 of shooting at A = 0.2 and
    0.5, the radius' lower bound real and positive, NaN beyond it."""
    m = mems1
    assert isinstance(m.RADIUS_LOWER, float) and 0 < m.RADIUS_LOWER <= m.RADIUS
    assert m.ALLOW_DIVERGENT is False
    for A in (0.2, 0.5):
        assert abs(m.omega(A) - 2 * np.pi / _shot_period(1, A)) <= 1e-8
    beyond = 1.01 * np.sqrt(m.RADIUS_LOWER)
    assert np.isnan(m.omega(beyond)) and np.isnan(m.error_estimate(beyond))
    assert np.isfinite(m.omega(0.99 * np.sqrt(m.RADIUS_LOWER)))


def test_mems_error_estimate_bounds_the_true_error_within_ten_times(mems1):
    """error_estimate against the period's true error (shooting, trusted to ~1e-12) on a grid
    of A: never below it, at most 10× above it where it is above rounding."""
    checked = 0
    for A in (0.3, 0.5, 0.65, 0.8, 0.9):
        true = abs(mems1.period(A) / _shot_period(1, A) - 1)
        estimate = mems1.error_estimate(A)
        assert estimate >= true or true < 1e-12, (A, estimate, true)
        if true > 1e-11:
            assert estimate <= 10 * true, (A, estimate, true)
            checked += 1
    assert checked >= 2


def test_mems_mode_2_series_meets_shooting_inside_its_bound():
    """Mode 2 (a complex pair of singularities: Mercer–Roberts): its lower bound real and
    positive, the order-8 sum within 1e-8 of shooting at A = 0.2 and 0.5."""
    from lindstedt.derive.nnm import radius

    series = _mems_series(2)
    bound = radius(series)
    assert 0.5 < bound.reach < bound.estimate ** 0.5
    tau = [float(c) for c in series.period()[:9]]
    for A in (0.2, 0.5):
        model = 2 * np.pi * np.polyval(tau[::-1], A * A)
        assert abs(2 * np.pi / model - 2 * np.pi / _shot_period(2, A)) <= 1e-8


def test_mems_allow_divergent_lifts_the_guard_and_a_bound_of_zero_is_refused(monkeypatch):
    from lindstedt.derive.nnm import ModeRadius
    from lindstedt.errors import InputError
    from lindstedt.lower import series as lowering

    series = _mems_series(1)
    guarded = lowering.lower_periodic(series, "test", 4, "m")
    free = lowering.lower_periodic(series, "test", 4, "m", allow_divergent=True)
    assert dict(free.constants)["ALLOW_DIVERGENT"] is True
    lower = dict(guarded.constants)["RADIUS_LOWER"]
    assert any(abs(float(f) - lower) < 1e-9 for f in guarded.evaluators[0].guard.atoms(
        sp.Float)) and not any(abs(float(f) - lower) < 1e-9 for f in
                               free.evaluators[0].guard.atoms(sp.Float))
    monkeypatch.setattr(lowering, "mode_radius", lambda mode: ModeRadius(1.0, 5.0, 0.0, "test", 2))
    with pytest.raises(InputError, match="every amplitude would be NaN"):
        lowering.lower_periodic(series, "test", 4, "m")
    assert lowering.lower_periodic(series, "test", 4, "m", allow_divergent=True)


SWINGING = ("1.2*x1'' + 0.3*x2'' + 2.5*x1 - 0.7*x2 + 0.9*x1**3 = 0; "
            "0.3*x1'' + 0.8*x2'' - 0.7*x1 + 1.6*x2 + 0.4*x2**3 + 0.2*x1**2*x2 = 0")
# NOTE: mode 2's ω_j swing in size from order to order: no singularity fits them (no radius
# estimate), and the module used to answer at every amplitude (T(3) = 33.8 against a shot
# 0.981).


def test_a_mode_without_a_radius_estimate_still_has_a_bound(tmp_path):
    """No estimate: the bound is the smallest coefficient ratio; NaN beyond it, and inside it
    error_estimate is never below the period's true error (shooting)."""
    out = run("generate", SWINGING, "--mode", "2", "--order", "6", "--out", tmp_path)
    assert out.returncode == 0, out.stderr
    m = _load(tmp_path / "mode2.py", "swinging2")
    assert math.isnan(m.RADIUS) and 0 < m.RADIUS_LOWER < 1
    reach = math.sqrt(m.RADIUS_LOWER)
    assert np.isnan(m.period(3.0)) and np.isnan(m.period(1.01 * reach))
    series = normal_mode(parse_system(SWINGING), 2, 8)
    for A in (0.5 * reach, 0.9 * reach):
        period, starts = _evaluate(series, A)
        true = abs(m.period(A) / _shoot(SWINGING, A, starts[1:], period / 2)[1] - 1)
        assert m.error_estimate(A) >= true or true < 1e-12, (A, m.error_estimate(A), true)


def test_one_lowering_of_a_one_coordinate_oscillator_as_a_series_and_as_a_mode(tmp_path):
    """Free L–P is the normal-mode method at n = 1, and one lowering emits both: Duffing
    q'' + q + q³/2 = 0 lowered from its one-coordinate series and from its one-coordinate
    normal mode gives the same period, frequency and motion; the period meets the elliptic
    integral (T = 4K(m)/√(1 + x), x = A²/2, m = x/(2(1 + x))) within error_estimate."""
    from lindstedt.derive.lindstedt import derive
    from lindstedt.derive.models import model_from_text
    from lindstedt.emit.render import render_module
    from lindstedt.lower.series import lower_periodic

    text, K = "q'' + q + q**3/2 = 0", 10
    as_series = lower_periodic(derive(model_from_text(text, K + 2), K + 2), "test")
    as_mode = lower_periodic(normal_mode(parse_system(text), 1, K + 2), "test", K, "one_mode")
    (tmp_path / "one_series.py").write_text(render_module(as_series))
    (tmp_path / "one_mode.py").write_text(render_module(as_mode))
    series, mode = _load(tmp_path / "one_series.py", "one_series"), _load(
        tmp_path / "one_mode.py", "one_mode")
    assert mode.ORDER == series.ORDER == K and hasattr(series, "qdot")
    A = np.array([0.1, 0.4, 0.8])
    x = A**2 / 2
    exact = np.array([float(4 * mpmath.ellipk(v / (2 * (1 + v))) / mpmath.sqrt(1 + v))
                      for v in x])
    for m in (series, mode):
        assert np.all(np.abs(m.period(A) / exact - 1) <= np.maximum(m.error_estimate(A), 1e-14))
        np.testing.assert_allclose(m.omega(A) * exact / (2 * np.pi), 1, rtol=1e-6)
    np.testing.assert_allclose(mode.period(A), series.period(A), rtol=1e-14)
    t = np.linspace(0, 7, 15)
    np.testing.assert_allclose(mode.q(t, 0.8), series.q(t, 0.8), rtol=0, atol=1e-14)
