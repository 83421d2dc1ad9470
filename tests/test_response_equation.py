"""`lindstedt response|subharmonic|mixing EQUATION`: a user's equation in, the same answers out.

The fold reference is independent of the package: the force written here as a Python function,
DOP853 (scipy, rtol 1e-12) on the equation and its variational equation, the branch of fixed
points of the period map parametrised by ``q(0)`` (Newton in ``(q̇(0), ω)``), and the fold where
``det(M − I)`` changes sign along it (a Floquet multiplier crossing +1), located by bisection.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np
import pytest
from lindstedt.analysis.mixing import duffing_mixing, equation_mixing
from lindstedt.analysis.response import response_equation
from lindstedt.analysis.subharmonic import subharmonic
from lindstedt.analysis.systems import driven_problem, notes_problem, response
from lindstedt.cli import main
from lindstedt.cli.driven import (
    mixing_equation_json,
    mixing_json,
    subharmonic_equation_json,
    subharmonic_equation_response,
    subharmonic_json,
)
from lindstedt.cli.response import response_json as printed_json
from lindstedt.costs import response_cost
from lindstedt.limits import COST_LIMIT_SECONDS
from scipy.integrate import solve_ivp

ASYMMETRIC = "q'' + 0.05*q' + q + 0.1*q**2 + 0.1*q**3 = 0.3*cos(w*t)"
FOLD_AGREE = 1e-7


def response_equation_json(text: str, values: dict[str, str], harmonics: int) -> dict:
    """``response EQUATION --json``'s contract: the record computed, then printed."""
    return printed_json(response(driven_problem(text, values), harmonics,
                                         max_seconds=COST_LIMIT_SECONDS))


def response_json(eps: float, force: float, Q: float, harmonics: int) -> dict:
    """``response --eps --force --Q --json``'s contract: the record computed, then printed."""
    de, closed = notes_problem(eps, force, Q)
    return printed_json(response(de, harmonics, max_seconds=COST_LIMIT_SECONDS,
                                         closed=closed))


def asymmetric(q, p):
    """``g(q, p)`` of ASYMMETRIC and its partial derivatives, written out by hand."""
    return (0.05 * p + q + 0.1 * q**2 + 0.1 * q**3, 1 + 0.2 * q + 0.3 * q**2, 0.05)


# --- the reference --------------------------------------------------------------------------

def _period_map(y0, omega, force=0.3, g=asymmetric):
    def rhs(t, y):
        val, gq, gp = g(y[0], y[1])
        return [y[1], force * math.cos(omega * t) - val,
                y[3], -gq * y[2] - gp * y[3], y[5], -gq * y[4] - gp * y[5]]

    sol = solve_ivp(rhs, (0.0, 2 * math.pi / omega), [y0[0], y0[1], 1.0, 0.0, 0.0, 1.0],
                    method="DOP853", rtol=1e-12, atol=1e-12)
    end = sol.y[:, -1]
    return end[:2], np.array([[end[2], end[4]], [end[3], end[5]]])


def _on_branch(q0, guess):
    """The fixed point of the period map with ``q(0) = q0``: Newton in ``(q̇(0), ω)``
    (∂/∂q̇(0) from the monodromy matrix, ∂/∂ω by a central difference); ``(p0, ω, det(M − I))``."""
    p0, omega = guess
    for _ in range(30):
        end, mono = _period_map((q0, p0), omega)
        h = 1e-6 * omega
        dw = (_period_map((q0, p0), omega + h)[0] - _period_map((q0, p0), omega - h)[0]) / (2 * h)
        J = np.column_stack([mono[:, 1] - [0.0, 1.0], dw])
        step = np.linalg.solve(J, -(end - [q0, p0]))
        p0, omega = p0 + step[0], omega + step[1]
        if np.max(np.abs(step)) < 1e-12:
            break
    _, mono = _period_map((q0, p0), omega)
    return p0, omega, float(np.linalg.det(mono - np.eye(2)))


def reference_fold(y0, omega, dq=0.02):
    """The fold near ``(y0, ω)``: det(M − I) along the branch through it, parametrised by q(0),
    bracketed within ±dq and bisected to 1e-6 in q(0)."""
    a, b = y0[0] - dq, y0[0] + dq
    pa = _on_branch(a, (y0[1], omega))
    pb = _on_branch(b, (y0[1], omega))
    assert np.sign(pa[2]) != np.sign(pb[2]), (pa, pb)
    for _ in range(40):
        m = 0.5 * (a + b)
        pm = _on_branch(m, (0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])))
        if np.sign(pm[2]) == np.sign(pa[2]):
            a, pa = m, pm
        else:
            b, pb = m, pm
        if b - a < 1e-6:  # ω is extremal at the fold: its error is ~(1e-6)²
            break
    return 0.5 * (pa[1] + pb[1])


# --- response EQUATION ------------------------------------------------------------------------

def test_folds_of_an_asymmetric_spring_against_the_reference():
    """Both folds of the continued balance and of the true orbit agree with the reference's;
    the sweeps jump just past them (up past the upper, down below the lower); the one-harmonic
    folds are the cubic's (q² has no first harmonic on r cos θ)."""
    data = response_equation_json(ASYMMETRIC, {}, 8)
    lo, hi = data["parameters"]["omega_range"]
    assert lo == 0.5 and 1.8 < hi < 1.9
    hb, true = data["harmonic_balance"]["folds"], data["numerical"]["folds"]
    assert len(hb) == len(true) == 2 and data["harmonic_balance"]["complete"]
    for moduli in data["numerical"]["fold_floquet_moduli"]:
        assert abs(max(moduli) - 1) < 1e-8 and min(moduli) < 1
    for w in true:  # the reference's fold from the package's fold orbit, moved off it
        from lindstedt.analysis.polynomial import driven_equation
        from lindstedt.numerics.integrate import ForceTable
        from lindstedt.numerics.shooting import orbit_fold_table

        de = driven_equation(ASYMMETRIC, {}, 1.0)
        _, y0, _ = orbit_fold_table(ForceTable.of(de.terms), de.force, w, _fold_state(data, w))
        ref = reference_fold(y0 + np.array([3e-3, 0.0]), w)
        assert abs(w - ref) < FOLD_AGREE, (w, ref)
        assert min(abs(h - ref) for h in hb) < FOLD_AGREE, (hb, ref)
    num = data["numerical"]
    assert 0 < num["sweep_up_jump"] - true[1] < 0.02
    assert 0 < true[0] - num["sweep_down_jump"] < 0.02
    assert num["sweep_up_escape"] is None and num["sweep_down_escape"] is None
    assert data["one_harmonic"]["folds"] == pytest.approx([1.161865303909, 1.489393339365],
                                                          abs=1e-11)


def _fold_state(data, w):
    """The balance's state at the fold ``w`` (the package's seed for its own refinement)."""
    from lindstedt.analysis.polynomial import PolynomialBalance, driven_equation
    from lindstedt.analysis.systems import continue_balance

    de = driven_equation(ASYMMETRIC, {}, 1.0)
    cont = continue_balance(de, 8, *data["parameters"]["omega_range"])
    x = cont.x[int(np.argmin(np.abs(cont.omega - w)))]
    return PolynomialBalance(de.terms, de.force, 8, de.odd).state(x, w)


def test_duffing_as_text_reproduces_the_flags():
    """Eq. 10.60 written out (another coordinate, Q a parameter): the same range, the same
    folds three ways to 1e-7, the same sweep jumps."""
    text = "x'' + x'/Q + x + eps*x**3 = f*cos(W*t)"
    mine = response_equation_json(text, {"eps": "1/10", "f": "3/10", "Q": "20"}, 8)
    flags = response_json(0.1, 0.3, 20.0, 8)
    assert mine["parameters"]["omega_range"] == pytest.approx(
        flags["parameters"]["omega_range"], abs=1e-12)
    for part in ("one_harmonic", "harmonic_balance", "numerical"):
        assert mine[part]["folds"] == pytest.approx(flags[part]["folds"], abs=1e-7), part
    for key in ("sweep_up_jump", "sweep_down_jump"):
        assert mine["numerical"][key] == pytest.approx(flags["numerical"][key], abs=1e-7)
    assert mine["parameters"]["drive"] == {"amplitude": 0.3, "frequency": "W"}


def test_the_preset_takes_the_equations_range(capsys):
    """``response --eps --force --Q --omega A:B`` (the preset with the general form's flag):
    the range given, the folds inside it equal to the written-out equation's over the same
    range; a reversed range refused in one line."""
    assert main(["response", "--eps", "0.1", "--force", "0.3", "--Q", "20", "--omega",
                 "1.2:1.6", "--json"]) == 0
    preset = json.loads(capsys.readouterr().out)
    assert main(["response", "x'' + x'/20 + x + x**3/10 = 3/10*cos(w*t)", "--omega", "1.2:1.6",
                 "--json"]) == 0
    written = json.loads(capsys.readouterr().out)
    assert preset["parameters"]["omega_range"] == [1.2, 1.6]
    assert written["parameters"]["omega_range"] == [1.2, 1.6]
    assert len(preset["numerical"]["folds"]) == 1  # the upper fold; the lower lies below 1.2
    assert written["numerical"]["folds"] == pytest.approx(preset["numerical"]["folds"],
                                                          abs=1e-9)
    assert main(["response", "--eps", "0.1", "--force", "0.3", "--Q", "20", "--omega",
                 "1.6:1.2"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_a_softening_spring_as_text_escapes_where_the_flags_do():
    text = "q'' + q'/20 + q - q**3/10 = 3/10*cos(w*t)"
    mine = response_equation_json(text, {}, 8)
    flags = response_json(-0.1, 0.3, 20.0, 8)
    assert mine["harmonic_balance"]["folds"] == pytest.approx(
        flags["harmonic_balance"]["folds"], abs=1e-9)
    num = mine["numerical"]
    assert num["sweep_up_jump"] is None
    assert num["sweep_up_escape"] == pytest.approx(flags["numerical"]["sweep_up_escape"],
                                                   abs=2e-3)


# --- subharmonic and mixing EQUATION ---------------------------------------------------------

def _without_added(data):
    data = {k: v for k, v in data.items()
            if k not in {"equation", "name", "n", "orbits", "primary", "onset", "seeds",
                         "note"}}
    data["parameters"] = {k: v for k, v in data["parameters"].items()
                          if k not in {"values", "harmonics"}}
    return data


@pytest.mark.parametrize("text, omega", [
    ("x'' + x + eps*x**3 = f*cos(3*w*t)", 1.2),  # w is ω
    ("y'' + y + eps*y**3 = f*cos(W*t)", 1.2),  # W is the drive, 3ω
])
def test_subharmonic_as_text_equals_the_flags(text, omega):
    found = subharmonic_equation_response(text, {"eps": "1/10", "f": "1/2"}, omega)
    mine = subharmonic_equation_json(text, "oscillator", *found)
    assert _without_added(mine) == subharmonic_json(0.1, 0.5, 1.2, subharmonic(0.1, 0.5, 1.2))
    assert mine["parameters"]["values"] == {"eps": "1/10", "f": "1/2"}


def test_mixing_as_text_equals_the_flags():
    text = "u'' + u'/Q + u + eps*u**3 = f2*cos(w2*t) + f1*cos(w1*t)"
    values = {"eps": "1/10", "Q": "10", "f1": "3/10", "w1": "13/10", "f2": "1/5",
              "w2": "17/10"}
    mine = mixing_equation_json(equation_mixing(text, values), text)
    assert _without_added(mine) == mixing_json(duffing_mixing(0.1, 10.0, [(0.3, 1.3),
                                                                          (0.2, 1.7)]))


# --- refusals and costs ----------------------------------------------------------------------

@pytest.mark.parametrize("argv, says", [
    (["subharmonic", "q'' + q'/20 + q = cos(w*t)/2", "--omega", "1", "--n", "2"],
     "a linear force has no subharmonic"),
    (["subharmonic", "q'' + q'/20 + q + q**2 = f*cos(w*t)", "--omega", "1", "--n", "2",
      "--param", "f=0"], "the drive vanishes with the values given"),
    (["subharmonic", "q'' + q + q**3/10 = cos(w*t)/2", "--omega", "1", "--n", "1"],
     "--n 1: the subharmonic's order must be an integer in 2..12"),
    (["subharmonic", "--eps", "0.1", "--force", "0.5", "--omega", "1.2", "--n", "2"],
     "give an EQUATION for another n"),
    (["subharmonic", "q'' + q + q**3/10 = cos(w*t)/2 + cos(2*w*t)", "--omega", "1"],
     "2 drive terms"),
    (["mixing", "q'' + q'/10 + q + q**3/10 = cos(w*t)/2"], "give w a value"),
    (["mixing", "q'' + q + q**3/10 = cos(t)/2"], "mixing needs a linear damping term"),
    (["mixing", "q'' + q'/10 + q**3/10 = cos(t)/2"], "no linear term"),
    (["response", "q'' + q'/Q + q + eps*q**3 = f*cos(w*t)", "--param", "eps=1/10",
      "--param", "f=3/10"], "give Q a value"),
    (["response", "q'' + q + q**3/10 = cos(w*t)/2"], "no damping"),
    (["response", "q'' + w*q'/10 + q + q**3/10 = cos(w*t)/2"], "depends on the drive"),
    (["response", "q'' + q'/10 + q + q**3/10 = cos(w*t)/2", "--eps", "0.1"], "--eps"),
    (["response", "--eps", "0.1", "--force", "0.3", "--Q", "20", "--param", "a=1"],
     "give an equation"),
    (["subharmonic", "--eps", "0.1", "--force", "0.5"], "required: --omega"),
])
def test_refusals_exit_2_in_one_line(argv, says, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and len(err.splitlines()) == 1, err


def test_cost_bounds_response_equation():
    """The estimate before it runs bounds the work it does (in-process, without start-up)."""
    args = argparse.Namespace(command="response", model=ASYMMETRIC, param=None, name=None,
                              omega_min=None, omega_max=None, harmonics=8, eps=None,
                              force=None, Q=None, allow_slow=False)
    estimate = response_cost(args).seconds
    start = time.perf_counter()
    response_equation_json(ASYMMETRIC, {}, 8)
    assert time.perf_counter() - start < estimate < 60
    args.harmonics = 100
    assert response_cost(args).seconds > 60  # refused without --allow-slow


def test_response_equation_json_keys_keep_the_contract(capsys):
    assert main(["response", ASYMMETRIC, "--json", "--omega", "1.3:1.6"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"parameters", "one_harmonic", "harmonic_balance", "numerical"} <= data.keys()
    assert data["parameters"]["omega_range"] == [1.3, 1.6]
    assert {"folds", "sweep_up_jump", "sweep_down_jump", "sweep_resolution", "sweep_up_escape",
            "sweep_down_escape"} <= data["numerical"].keys()
    assert len(data["numerical"]["folds"]) == 1  # only the upper fold lies in [1.3, 1.6]


@pytest.mark.parametrize("eps, force, Q, folds", [
    (0.1, 0.3, 185.0, (1.164938605148117, 3.963272238735694)),
    (1.0, 0.05, 185.0, (1.1103722095597486, 2.9199877180685214)),
    (0.01, 0.05, 1e4, (1.0247962306602898, 6.618470884248357)),
    (0.1, 0.3, 20.0, (1.1618653039085556, 1.4893933393651175))])
def test_a_high_q_equation_keeps_its_upper_fold(eps, force, Q, folds):
    """Eq. 10.60 written out as a user's equation (the response EQUATION path): its range
    holds both one-harmonic folds, each the cubic's closed form's (tests/test_response.py's
    references, to two units in the last place): the upper fold far out (ω = 3.963 at
    Q = 185, 6.6 at Q = 1e4) was once lost, and the range with it."""
    from lindstedt.analysis.response import response_range

    de = response_equation(f"q'' + q'/{Q!r} + q + {eps!r}*q**3 = {force!r}*cos(w*t)", {})
    span = response_range(de.terms, de.force)
    np.testing.assert_allclose(span.one_harmonic_folds, folds, rtol=5e-16, atol=0)
    assert span.omega_range == (0.5 * min(1.0, folds[0]), 1.25 * folds[1])
