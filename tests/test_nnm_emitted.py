"""The emitted normal-mode module: its ufuncs against the exact series and against shooting,
NaN beyond the radius, the ``_into`` twins, and bad input for ``generate SYSTEM``."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
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
])
def test_generate_system_refusals_write_nothing(tmp_path, args, says):
    out = run("generate", KERSCHEN, *args, "--out", str(tmp_path / "new"))
    assert out.returncode == 2 and out.stdout == ""
    assert len(out.stderr.strip().splitlines()) == 1 and says in out.stderr, out.stderr
    assert not (tmp_path / "new").exists()


def test_mode_flag_without_a_system_is_refused():
    out = run("generate", "duffing", "--mode", "2", "--out", "x")
    assert out.returncode == 2 and "a system's flags" in out.stderr
