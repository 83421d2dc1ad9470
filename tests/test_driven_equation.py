"""`lindstedt driven EQUATION`: every 1:1 orbit of a user's driven oscillator, each checked.

The reference is independent of the package: the force written here as a Python function,
DOP853 (scipy, rtol 1e-12) on the equation and its variational equation, Newton's method on the
period map, and this file's own seeds from the one-harmonic balance (the first harmonic of the
force on ``q = r cos θ`` by an FFT, its roots in r on a fine grid).  Each orbit the package
reports must be a reference orbit (Newton from it stays there) with the same r, Floquet moduli
and verdict, no two the same, and Newton from every one of this file's seeds must land on one
of them.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from lindstedt.analysis.driven import Drive
from lindstedt.analysis.periodic import driven_report, periodic_orbits
from lindstedt.analysis.polynomial import driven_equation
from lindstedt.cli import main
from lindstedt.cli.driven import driven_equation_report_json
from scipy.integrate import solve_ivp

AGREE = 1e-7  # the package's orbit against the reference's (state, relative; r)
SAME = 1e-6  # two reference orbits are one

ASYMMETRIC = "q'' + q + eps*(q**2 + q**3) + gamma*q'**3 = f*cos(w*t)"


def driven_equation_json(text: str, values: dict[str, str], omega: float,
                         harmonics: int) -> dict:
    """``driven EQUATION --json``'s contract: the record computed, then printed."""
    return driven_equation_report_json(
        driven_report(driven_equation(text, values, omega, "oscillator"), 0, harmonics))


def asymmetric(eps, gamma):
    """``g(q, p)`` of ASYMMETRIC and its partial derivatives, written out by hand."""
    def g(q, p):
        return (q + eps * (q**2 + q**3) + gamma * p**3,
                1 + eps * (2 * q + 3 * q**2), 3 * gamma * p**2)
    return g


# --- the reference ------------------------------------------------------------------------------

def _flow(g, force, omega, y0, samples=None):
    T = 2 * math.pi / omega

    def rhs(t, y):
        val, gq, gp = g(y[0], y[1])
        return [y[1], force * math.cos(omega * t) - val,
                y[3], -gq * y[2] - gp * y[3], y[5], -gq * y[4] - gp * y[5]]

    t_eval = None if samples is None else np.linspace(0, T, samples + 1)
    sol = solve_ivp(rhs, (0.0, T), [y0[0], y0[1], 1.0, 0.0, 0.0, 1.0], method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=t_eval)
    end = sol.y[:, -1]
    return end[:2], np.array([[end[2], end[4]], [end[3], end[5]]]), sol.y[0, :-1]


def reference_orbit(g, force, omega, y0, dissipative):
    """Newton on ``P(y) − y = 0``: ``(state, r, moduli, stable)`` or ``None``."""
    y = np.array(y0, dtype=float)
    for _ in range(40):
        end, mono, _ = _flow(g, force, omega, y)
        if not np.all(np.isfinite(end)) or np.max(np.abs(y)) > 1e3:
            return None
        step = np.linalg.solve(mono - np.eye(2), y - end)
        y = y + step
        if np.max(np.abs(step)) < 1e-11 * (1 + np.max(np.abs(y))):
            break
    else:
        return None
    end, mono, q = _flow(g, force, omega, y, samples=256)
    lam = np.linalg.eigvals(mono)
    stable = bool(np.all(np.abs(lam) < 1)) if dissipative else bool(abs(np.trace(mono)) < 2)
    c1 = np.mean(q * np.exp(-2j * np.pi * np.arange(len(q)) / len(q)))
    return y, float(2 * abs(c1)), sorted(float(abs(m)) for m in lam), stable


def one_harmonic_seeds(g, force, omega, r_max=8.0):
    """``q = r cos(ωt − φ)``: the first harmonic ``V(r)`` of ``q̈ + g`` must be ``f e^{−iφ}``:
    the roots of ``|V(r)| = f`` on a fine grid, each as ``(q(0), q̇(0))``."""
    theta = 2 * np.pi * np.arange(64) / 64

    def V(r):
        val, _, _ = g(r * np.cos(theta), -omega * r * np.sin(theta))
        c = 2 * np.mean(val * np.exp(-1j * theta))  # cos part c.real, sin part −c.imag
        return complex(c.real - omega**2 * r, -c.imag)

    rs = np.linspace(1e-3, r_max, 8000)
    h = np.array([abs(V(r)) - force for r in rs])
    seeds = []
    for i in np.nonzero(np.sign(h[:-1]) != np.sign(h[1:]))[0]:
        lo, hi = rs[i], rs[i + 1]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if np.sign(abs(V(mid)) - force) == np.sign(h[i]):
                lo = mid
            else:
                hi = mid
        v = V(lo)
        phi = math.atan2(-v.imag, v.real)
        seeds.append(np.array([lo * math.cos(phi), omega * lo * math.sin(phi)]))
    return seeds


def _distance(a, b, omega):
    u, v = np.array([a[0], a[1] / omega]), np.array([b[0], b[1] / omega])
    return float(np.linalg.norm(u - v) / max(np.linalg.norm(u), np.linalg.norm(v)))


def check_against_reference(text, values, omega, g, force, dissipative=True):
    found = periodic_orbits(driven_equation(text, values, omega))
    assert found.complete, found.note
    refs = []
    for mine in found.orbits:
        assert mine.orbit is not None
        ref = reference_orbit(g, force, omega, mine.orbit.initial, dissipative)
        assert ref is not None, (omega, mine.r)
        state, r, moduli, stable = ref
        assert _distance(mine.orbit.initial, state, omega) < AGREE, (omega, r)
        assert abs(mine.r - r) < AGREE * r, (omega, mine.r, r)
        assert mine.orbit.stable == stable, (omega, r)
        got = sorted(float(abs(m)) for m in mine.orbit.multipliers)
        assert np.allclose(got, moduli, atol=1e-6), (omega, got, moduli)
        assert all(_distance(state, other[0], omega) > SAME for other in refs)  # each once
        refs.append(ref)
    seeds = one_harmonic_seeds(g, force, omega)
    assert seeds
    for seed in seeds:  # nothing the package missed
        ref = reference_orbit(g, force, omega, seed, dissipative)
        assert ref is not None
        assert any(_distance(ref[0], mine[0], omega) < AGREE for mine in refs), (omega, ref[1])
    return found.orbits


# --- (a) q'' + q + eps(q² + q³) + γq'³ = f cos ωt -------------------------------------------------

VALUES = {"eps": "1/10", "gamma": "1/100", "f": "3/10"}


@pytest.mark.parametrize("omega,stable", [
    (1.2, [True, False, True]),  # inside the fold window: three orbits, the middle unstable
    (1.25, [True, False, True]),
    (1.5, [True]),  # beyond its upper fold
    (1.0, [True]),  # the linear resonance (undamped linear part: the curve starts degenerate)
])
def test_asymmetric_spring_with_cubic_damping(omega, stable):
    orbits = check_against_reference(ASYMMETRIC, VALUES, omega, asymmetric(0.1, 0.01), 0.3)
    assert [o.orbit.stable for o in orbits] == stable
    rs = [o.r for o in orbits]
    assert rs == sorted(rs, reverse=True)


def test_the_documented_example_and_its_json():
    """γ = 1/20 at ω = 1.2: one orbit, with its constant term and even harmonics (the force is
    not odd), the balance agreeing with shooting."""
    values = {"eps": "1/10", "gamma": "1/20", "f": "3/10"}
    (orbit,) = check_against_reference(ASYMMETRIC, values, 1.2, asymmetric(0.1, 0.05), 0.3)
    data = driven_equation_json(ASYMMETRIC, values, 1.2, 8)
    assert data["odd"] is False and data["parameters"]["drive"] == {"amplitude": 0.3,
                                                                    "frequency": "w"}
    (br,) = data["branches"]
    hb, num = br["harmonic_balance"], br["numerical"]
    assert hb["converged"] and set(hb["A"]) >= {"0", "1", "2", "3"} and "2" in hb["B"]
    assert abs(num["A"]["0"]) > 1e-2  # the q² term shifts the mean
    for k in ("0", "1", "2", "3"):
        assert abs(hb["A"][k] - num["A"][k]) < 1e-8
    assert br["stable"] is True and abs(br["r"] - orbit.r) < 1e-12
    assert np.allclose(num["floquet_moduli"], sorted(abs(m) for m in orbit.orbit.multipliers))
    json.dumps(data)


# --- (b) Duffing as text: the built-in orbits ----------------------------------------------------

@pytest.mark.parametrize("Q,omega", [
    (20.0, 1.491), (20.0, 1.4932),  # 3e-5 below the true fold, 1.4932319: two orbits 3e-3 apart
    (20.0, 0.8), (math.inf, 1.2)])
def test_duffing_as_text_reproduces_the_built_in(Q, omega):
    values = {"eps": "1/10", "f": "3/10"}
    text = "q'' + q + eps*q**3 = f*cos(w*t)"
    if math.isfinite(Q):
        text, values["Q"] = "q'' + q'/Q + q + eps*q**3 = f*cos(w*t)", "20"
    mine = periodic_orbits(driven_equation(text, values, omega)).orbits
    built = periodic_orbits(Drive(0.1, 0.3, omega, Q)).orbits
    assert len(mine) == len(built) == (1 if omega == 0.8 else 3)
    for a, b in zip(mine, built, strict=True):
        assert np.max(np.abs(a.orbit.initial - b.orbit.initial)) < 1e-8
        assert a.orbit.stable == b.orbit.stable
        assert np.allclose(sorted(abs(m) for m in a.orbit.multipliers),
                           sorted(abs(m) for m in b.orbit.multipliers), atol=1e-8)
        for n in (1, 3, 5):
            assert abs(a.orbit.A[n] - b.orbit.A[n]) < 1e-8
            assert abs(a.orbit.B[n] - b.orbit.B[n]) < 1e-8


# --- (c) refusals: one line, exit 2, nothing on stdout -------------------------------------------

@pytest.mark.parametrize("argv,says", [
    ([ASYMMETRIC, "--param", "eps=1/10", "--param", "f=3/10"], "give gamma a value"),
    (["q'' + sin(q) = f*cos(w*t)", "--param", "f=1/10"], "not a polynomial"),
    (["q'' + q + a*q*cos(w*t) = f*cos(w*t)", "--param", "a=1/10", "--param", "f=1/10"],
     "parametric"),
    (["q'' + q + eps*q**3 = f*cos(w*t) + g*cos(2*w*t)", "--param", "eps=1/10", "--param",
      "f=1/10", "--param", "g=1/10"], "has 2 terms"),
    (["q'' + q = f*sin(w*t)", "--param", "f=1/10"], "not f*cos(w*t)"),
    (["q'' + q + eps*q**3 = 0", "--param", "eps=1/10"], "no drive"),
    (["q'' + q = f*cos(w*t)", "--param", "f=1/10", "--param", "w=2"], "--omega"),
    (["q'' + q = f*cos(w*t)", "--param", "f=1/10", "--eps", "0.1"], "--eps"),
    (["--eps", "0.1"], "required: --force"),  # eq. 10.60 as before
])
def test_refusals(argv, says, capsys):
    assert main(["driven", *argv, "--omega", "1.2"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and says in err, err


def test_cost_bounds_the_equation_path():
    """The estimate covers `driven EQUATION` (the μ-expansion's --order plays no part) and
    bounds its measured wall time."""
    import time

    from lindstedt.cli import build_parser
    from lindstedt.costs import COSTS

    argv = ["driven", ASYMMETRIC, "--omega", "1.2", "--order", "200", "--harmonics", "20"]
    for pair in VALUES.items():
        argv += ["--param", "=".join(pair)]
    cost = COSTS["driven"](build_parser().parse_args(argv))
    assert "harmonics 20" in cost.subject and cost.seconds < 60
    start = time.perf_counter()
    periodic_orbits(driven_equation(ASYMMETRIC, VALUES, 1.2), 20)
    assert time.perf_counter() - start < cost.seconds


def test_the_full_hill_verdict_of_each_balance_against_dop853():
    """`driven EQUATION` reports the full Hill equation's multipliers about each balance (the
    variational equation about the N-harmonic sum, one RK4 pass); with a linear velocity term
    they are the true orbit's Floquet moduli, which the reference finds by DOP853 and Newton
    on the return map: q'' + 0.05q' + q + ε(αq² + q³) = f cos ωt inside its fold window."""
    from lindstedt.analysis.periodic import driven_report

    text = "q'' + 0.05*q' + q + eps*(alpha*q**2 + q**3) = f*cos(w*t)"
    values = {"eps": "1/10", "alpha": "1", "f": "3/10"}

    def g(q, p):
        return (q + 0.1 * (q**2 + q**3) + 0.05 * p, 1 + 0.1 * (2 * q + 3 * q**2), 0.05)

    report = driven_report(driven_equation(text, values, 1.2), 0, 12)
    assert len(report.branches) == 3
    for b in report.branches:
        assert b.full_hill is not None and b.balance_amplitudes is not None
        _, r, moduli, stable = reference_orbit(g, 0.3, 1.2, b.orbit.orbit.initial, True)
        hill = sorted(float(abs(m)) for m in b.full_hill)
        assert np.allclose(hill, moduli, rtol=1e-6), (r, hill, moduli)
        assert (max(hill) < 1) == stable
    data = driven_equation_json(text, values, 1.2, 12)
    assert [br["harmonic_balance"]["full_hill_stable"] for br in data["branches"]] \
        == [br["stable"] for br in data["branches"]] == [True, False, True]
