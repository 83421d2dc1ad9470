"""Response curves: folds of the cubic, continuation, true folds, sweep jumps (§10.4)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from generator.driven import Drive
from generator.numerics import orbit_fold, shoot, sweep
from generator.response import (
    amplitude_residual,
    amplitude_slope,
    continue_balance,
    one_harmonic_curve,
    one_harmonic_folds,
)

EPS, F, Q = 0.1, 0.3, 20.0


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


def test_folds_are_double_roots_and_change_the_branch_count():
    folds = one_harmonic_folds(EPS, F, Q)
    assert len(folds) == 2
    d = Drive(EPS, F, 1.0, Q)
    for w in folds:
        assert len(cubic_roots(w - 1e-7)) + len(cubic_roots(w + 1e-7)) == 4  # 1 | 3
        # a double root u: G(u) = ∂G/∂u = 0 to rounding
        u = np.roots([27 / 16 * EPS**2, 3 * EPS * (1 - w**2), (1 - w**2) ** 2 + w**2 / Q**2])
        u = min((x.real for x in u if abs(x.imag) < 1e-6 and x.real > 0),
                key=lambda x: abs(amplitude_residual(x, w, d)))
        assert abs(amplitude_residual(u, w, d)) < 1e-12
        assert abs(amplitude_slope(u, w, d)) < 1e-12


def test_balance_folds_are_true_folds_with_floquet_multiplier_one():
    cont = continue_balance(EPS, F, Q, 8, 0.6, 1.9)
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
    lo, hi = one_harmonic_folds(EPS, F, Q)
    cont = continue_balance(EPS, F, Q, 8, 0.6, 1.9)
    up = sweep(EPS, F, 1 / Q, 0.6, 1.9)
    down = sweep(EPS, F, 1 / Q, 1.9, 0.6)
    resolution = 0.01  # Δω of the jump window at 10⁴ periods, and the slow-passage lag
    assert abs(up.jump - cont.folds[1]) < resolution
    assert abs(down.jump - cont.folds[0]) < resolution
    assert sweep(EPS, 0.05, 1 / Q, 0.6, 1.9).jump is None  # no hysteresis, no jump
    assert lo < hi


def test_response_contract_and_bad_input():
    out = subprocess.run([sys.executable, "-m", "generator", "response", "--eps", "0.1",
                          "--force", "0.3", "--Q", "20", "--harmonics", "4", "--json"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["one_harmonic"]["folds"] == sorted(data["one_harmonic"]["folds"])
    assert data["harmonic_balance"]["harmonics"] == 4
    assert len(data["numerical"]["folds"]) == 2
    assert {"sweep_up_jump", "sweep_down_jump"} <= data["numerical"].keys()
    for bad in (["--Q", "inf"], ["--Q", "0"], ["--Q", "nan"]):
        run = subprocess.run([sys.executable, "-m", "generator", "response", "--eps", "0.1",
                              "--force", "0.3", *bad], capture_output=True, text=True,
                             check=False)
        assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("omega", [np.array([0.0]), np.array([np.nan])])
def test_curve_bad_frequency(omega):
    from generator.errors import InputError

    with pytest.raises(InputError):
        one_harmonic_curve(EPS, F, Q, omega)
