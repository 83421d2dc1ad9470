"""Every distinct 1:1 orbit at every ω, each once, with its Floquet verdict (`driven`).

The reference here is independent of the package: DOP853 (scipy, rtol 1e-12) on the equation
and its variational equation, Newton's method on the period map, and the true folds as
``P(y) = y`` with ``det(M − I) = 0`` (a Floquet multiplier +1) by Newton's method in
``(y, ω)``.  Inside a hysteresis window (between the folds) the hardening oscillator has three
orbits, outside one.  At each ω every orbit the package reports must be a reference orbit
(Newton from it stays there) with the same r, multipliers and verdict, no two the same, as
many as the reference folds say, and Newton from this file's own one-harmonic roots must find
no orbit the package missed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from lindstedt.analysis.driven import Drive
from lindstedt.analysis.periodic import driven_report, periodic_orbits
from lindstedt.cli.driven import driven_report_json, driven_table
from scipy.integrate import solve_ivp

SAME = 1e-7  # two reference orbits are one when their states differ by this, relative
AGREE = 1e-7  # the package's orbit against the reference's (state, relative; and r)


# --- the reference ------------------------------------------------------------------------------

def _rhs(t, y, eps, force, omega, damping):
    q, p = y[0], y[1]
    k = -1.0 - 3.0 * eps * q * q
    return [p, force * math.cos(omega * t) - damping * p - q - eps * q**3,
            y[3], k * y[2] - damping * y[3], y[5], k * y[4] - damping * y[5]]


def _flow(y0, eps, force, omega, damping, samples=None):
    """State and monodromy after one period; with ``samples``, also q at that many points."""
    T = 2 * math.pi / omega
    t = None if samples is None else np.linspace(0, T, samples + 1)
    sol = solve_ivp(_rhs, (0.0, T), [y0[0], y0[1], 1.0, 0.0, 0.0, 1.0], method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=t, args=(eps, force, omega, damping))
    end = sol.y[:, -1]
    return end[:2], np.array([[end[2], end[4]], [end[3], end[5]]]), sol.y[0, :-1]


def reference_orbit(y0, eps, force, omega, damping, known=()):
    """Newton on ``P(y) − y = 0``: ``(state, r, moduli, stable)``, or ``None`` when it does not
    converge or runs onto one of the ``known`` orbits (then that one, found already)."""
    y = np.array(y0, dtype=float)
    for _ in range(30):
        end, mono, _ = _flow(y, eps, force, omega, damping)
        if not np.all(np.isfinite(end)) or np.max(np.abs(y)) > 1e3:
            return None
        try:
            step = np.linalg.solve(mono - np.eye(2), y - end)
        except np.linalg.LinAlgError:
            return None
        y = y + step
        if any(_distance(y, k[0], omega) < 1e-6 for k in known):
            return None
        if np.max(np.abs(step)) < 1e-11 * (1 + np.max(np.abs(y))):
            break
    end, mono, q = _flow(y, eps, force, omega, damping, samples=256)
    if np.max(np.abs(end - y)) > 1e-9 * (1 + np.max(np.abs(y))):
        return None
    lam = np.linalg.eigvals(mono)
    stable = bool(np.all(np.abs(lam) < 1)) if damping > 0 else bool(abs(np.trace(mono)) < 2)
    c1 = np.mean(q * np.exp(-2j * np.pi * np.arange(len(q)) / len(q)))  # first harmonic
    return y, float(2 * abs(c1)), sorted(float(abs(m)) for m in lam), stable


def _distance(a, b, omega):
    u, v = np.array([a[0], a[1] / omega]), np.array([b[0], b[1] / omega])
    return float(np.linalg.norm(u - v) / max(np.linalg.norm(u), np.linalg.norm(v)))


def _cubic_seeds(eps, force, omega, damping):
    """This file's own one-harmonic roots: ``u[(1 − ω² + ¾εu)² + ω²/Q²] = f²``, ``u = r²``."""
    a = 1 - omega**2
    seeds = []
    for u in np.roots([9 / 16 * eps**2, 1.5 * eps * a, a * a + omega**2 * damping**2,
                       -force**2]):
        if abs(u.imag) < 1e-9 * abs(u) and u.real > 0:
            r = math.sqrt(u.real)
            # a cos ωt + b sin ωt: a(1 − ω² + ¾εr²) + bω/Q = f, b(…) − aω/Q = 0
            s = a + 0.75 * eps * r * r
            det = s * s + (omega * damping) ** 2
            A, B = force * s / det, force * omega * damping / det
            seeds.append(np.array([A, omega * B]))
    return seeds


def reference_fold(eps, force, Q, omega, which):
    """The true fold next to ω: Newton in ``(q(0), q̇(0), ω)`` on ``P(y) − y = 0`` and
    ``det(M − I) = 0`` (central differences), from the orbit of this file's one-harmonic root
    ``which`` (0 the largest, −1 the smallest) at ω."""
    damping = 1 / Q
    seeds = sorted(_cubic_seeds(eps, force, omega, damping),
                   key=lambda s: -math.hypot(s[0], s[1] / omega))
    z = np.array([*reference_orbit(seeds[which], eps, force, omega, damping)[0], omega])

    def F(z):
        end, mono, _ = _flow(z[:2], eps, force, z[2], damping)
        return np.array([*(end - z[:2]), np.linalg.det(mono - np.eye(2))])

    for _ in range(20):
        J = np.empty((3, 3))
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1e-6 * (1 + abs(z[k]))
            J[:, k] = (F(z + e) - F(z - e)) / (2 * e[k])
        dz = np.linalg.solve(J, -F(z))
        z = z + dz
        if np.max(np.abs(dz)) < 1e-10:
            return float(z[2])
    raise AssertionError("the reference fold did not converge")


# --- the package against it ---------------------------------------------------------------------

def check_against_reference(eps, force, Q, omega):
    """The package's orbits at ω, each checked against the reference (see the docstring)."""
    damping = 0.0 if math.isinf(Q) else 1 / Q
    orbits = periodic_orbits(Drive(eps, force, omega, Q)).orbits
    rs = [o.r for o in orbits]
    assert rs == sorted(rs, reverse=True)
    refs = []
    for mine in orbits:
        ref = reference_orbit(mine.orbit.initial, eps, force, omega, damping)
        assert ref is not None, (omega, mine.r)
        state, r, moduli, stable = ref
        assert _distance(mine.orbit.initial, state, omega) < AGREE, (omega, r)
        assert abs(mine.r - r) < AGREE * r, (omega, mine.r, r)
        assert mine.orbit.stable == stable, (omega, r)
        got = sorted(float(abs(m)) for m in mine.orbit.multipliers)
        assert np.allclose(got, moduli, atol=1e-6), (omega, got, moduli)
        assert all(_distance(state, other[0], omega) > SAME for other in refs)  # each once
        refs.append(ref)
    for seed in _cubic_seeds(eps, force, omega, damping):  # nothing the package missed
        assert reference_orbit(seed, eps, force, omega, damping, known=refs) is None, omega
    return orbits


SWEEPS = [
    # ε, f, Q; the fold (ω and the one-harmonic root whose orbit starts its Newton); which side
    # of it is inside the hysteresis window; the ω swept.  Folds (reference; harmonic balance
    # N = 8 agrees to 1e-10): 1.4932319 (the cubic's: 1.48939), 1.1637939 (1.16360),
    # 1.4386701 (1.4377615), 2.2119353 (2.2046896); the other fold of each window is far.
    pytest.param(0.1, 0.3, 20.0, (1.489, 0), "below",
                 (1.485, 1.489, 1.491, 1.4925, 1.4932, 1.49323, 1.4935, 1.495),
                 id="upper-fold-Q20"),
    # between the folds the cubic has three roots and the true system one orbit
    pytest.param(0.1, 0.3, 30.0, (1.1638, -1), "above",
                 (1.16, 1.1636, 1.1637, 1.1638, 1.165, 1.17), id="lower-fold-Q30"),
    # ε = 1: the folds move further from the cubic's
    pytest.param(1.0, 0.5, 10.0, (1.439, -1), "above", (1.437, 1.438, 1.4387, 1.439, 1.44),
                 id="lower-fold-eps1"),
    pytest.param(1.0, 0.5, 10.0, (2.2, 0), "below",
                 (2.2, 2.204, 2.206, 2.21, 2.2119, 2.2125), id="upper-fold-eps1"),
    # a softening spring: the small in-well branch folds onto the middle one at 0.8044965 (the
    # cubic's: 0.80390); between the two the continued balance alone finds the two orbits
    pytest.param(-0.1, 0.3, 20.0, (0.8, -1), "below",
                 (0.795, 0.8, 0.803, 0.804, 0.8044, 0.8046, 0.806), id="softening-fold"),
]


@pytest.mark.parametrize("eps,force,Q,fold_seed,inside,omegas", SWEEPS)
def test_every_branch_through_the_fold_windows(eps, force, Q, fold_seed, inside, omegas):
    fold = reference_fold(eps, force, Q, *fold_seed)
    for w in omegas:
        orbits = check_against_reference(eps, force, Q, w)
        three = w < fold if inside == "below" else w > fold
        assert len(orbits) == (3 if three else 1), (w, fold, [o.r for o in orbits])
        if three:  # inside the loop: large and small stable, the middle one not
            assert [o.orbit.stable for o in orbits] == [True, False, True]


def test_undamped_branches_each_once():
    """Q = inf: no continuation, the cubic's roots only, each orbit once."""
    for w in (1.2, 1.3):
        assert len(check_against_reference(0.1, 0.3, math.inf, w)) == 3


# --- the JSON contract at the documented cases ----------------------------------------------

def test_omega_1491_reports_the_orbits_the_cubic_has_lost():
    """The cubic folds at 1.48939, the true system at 1.493232: at ω = 1.491 it has one root
    (r = 0.2457) and the system three orbits (verified against DOP853 shooting)."""
    d = Drive(0.1, 0.3, 1.491, 20.0)
    data = driven_report_json(driven_report(d, 4, 8))
    top, middle, small = data["branches"]
    assert abs(top["numerical"]["r"] - 3.995731) < 1e-6 and top["numerical"]["stable"]
    assert np.allclose(top["numerical"]["floquet_moduli"], [0.900, 0.900], atol=5e-4)
    assert abs(middle["numerical"]["r"] - 3.973835) < 1e-6 and not middle["numerical"]["stable"]
    assert np.allclose(middle["numerical"]["floquet_moduli"], [0.742, 1.092], atol=5e-4)
    assert abs(small["numerical"]["r"] - 0.2457) < 1e-4 and small["numerical"]["stable"]
    keys = {"A1", "r", "delta0", "mu_expansion", "mu_converged", "mu_note", "harmonic_balance",
            "numerical", "seed"}
    for br in (top, middle):  # no one-harmonic root: no first-order numbers, and said so
        assert keys <= br.keys() and br["seed"] == "continuation"
        assert br["A1"] is None and br["r"] is None and br["delta0"] is None
        assert br["mu_expansion"] == [] and br["mu_converged"] is False
        assert "no one-harmonic root" in br["mu_note"]
        assert br["harmonic_balance"]["converged"]
        assert abs(br["harmonic_balance"]["r"] - br["numerical"]["r"]) < 1e-8
    assert small["seed"] == "one_harmonic" and abs(small["r"] - 0.245734) < 1e-6
    assert [e["order"] for e in small["mu_expansion"]] == [0, 1, 2, 3, 4]
    assert set(small["numerical"]) >= {"A", "B", "floquet_moduli", "stable", "r"}
    assert data["seeding"]["complete"] is True
    assert [root["branch"] for root in data["one_harmonic_roots"]] == [2]
    text = driven_table(data)
    assert text.count("\nbranch ") == 3 and "found by continuation" in text
    assert "true r = 3.995731" in text and "true r = 3.973835" in text
    # and ω = 1.4925, closer to the true fold
    rs = [o.r for o in periodic_orbits(Drive(0.1, 0.3, 1.4925, 20.0)).orbits]
    assert len(rs) == 3 and rs[0] > rs[1] > 3.9 > 0.3 > rs[2]


def test_omega_1489_no_orbit_twice_and_the_middle_one_found():
    """Two of the cubic's roots shoot onto one orbit (A1 = 0.381599, B1 = 3.971954): it is
    reported once, and the true middle orbit (r = 3.959978, unstable) beside it."""
    data = driven_report_json(driven_report(Drive(0.1, 0.3, 1.489, 20.0), 4, 8))
    top, middle, small = data["branches"]
    assert abs(top["numerical"]["A"]["1"] - 0.381599) < 1e-6
    assert abs(top["numerical"]["B"]["1"] - 3.971954) < 1e-6 and top["numerical"]["stable"]
    assert abs(middle["numerical"]["r"] - 3.959978) < 1e-6 and not middle["numerical"]["stable"]
    assert np.allclose(middle["numerical"]["floquet_moduli"], [0.724, 1.119], atol=5e-4)
    assert abs(middle["harmonic_balance"]["r"] - 3.959978) < 1e-6  # its own balance
    assert small["numerical"]["stable"] and small["numerical"]["r"] < 0.3
    # three roots, three orbits: each root stands for one (the middle by its rank)
    assert [root["branch"] for root in data["one_harmonic_roots"]] == [0, 1, 2]
    assert [br["first_order"] for br in data["branches"]] == ["shot", "rank", "shot"]
    assert [br["r"] for br in data["branches"]] == sorted(
        (br["r"] for br in data["branches"]), reverse=True)


def test_softening_folds_and_seeding_against_the_reference():
    """ε = −0.1, f = 0.3, Q = 20: the balance continuation starts on the small (in-well) branch
    and traces the whole curve, so `response` reports the fold of the in-well branch (it
    reported none: the continuation began on the resonant branch over the barrier and left the
    range without meeting it) and `driven`'s seeding is complete; the fold against the
    reference fold, and its side of the one-harmonic fold (numpy.roots' branch count)."""
    from lindstedt.analysis.systems import notes_problem, response
    from lindstedt.cli.response import response_json
    from lindstedt.limits import COST_LIMIT_SECONDS

    eps, force, Q = -0.1, 0.3, 20.0
    fold = reference_fold(eps, force, Q, 0.8, -1)
    de, closed = notes_problem(eps, force, Q)
    data = response_json(response(de, 8, max_seconds=COST_LIMIT_SECONDS, closed=closed))
    (balance,) = data["harmonic_balance"]["folds"]
    (true,) = data["numerical"]["folds"]
    assert abs(true - fold) < 1e-8 and abs(balance - fold) < 1e-8
    (cubic,) = data["one_harmonic"]["folds"]
    assert cubic < fold
    for w, count in ((cubic - 1e-6, 3), (cubic + 1e-6, 1)):
        assert len(_cubic_seeds(eps, force, w, 1 / Q)) == count
    for w in (0.5, 0.8, 0.804, 1.0):
        found = periodic_orbits(Drive(eps, force, w, Q))
        assert found.complete, (w, found.note)
