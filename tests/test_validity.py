"""Every perturbative answer carries its validity: frequency mixing's expansion parameter and
verdict, and the simulated tones' uncertainty, against an independent DOP853 reference."""

from __future__ import annotations

import json

import numpy as np
from commands import run_forked
from scipy.integrate import solve_ivp


def reference_tones(eps, Q, drives, frequencies, window=2000.0):
    """The steady state's amplitude at each frequency: DOP853 at rtol 1e-11 from rest, 40 Q
    time units of transients, then a least-squares fit over ``window``."""
    F = np.array([f for f, _ in drives])
    W = np.array([w for _, w in drives])

    def rhs(t, y):
        return [y[1], -y[1] / Q - y[0] - eps * y[0] ** 3 + np.sum(F * np.cos(W * t))]

    settle = 40 * Q
    ts = np.linspace(settle, settle + window, 40001)
    sol = solve_ivp(rhs, (0, settle + window), [0.0, 0.0], method="DOP853", rtol=1e-11,
                    atol=1e-13, t_eval=ts)
    X = np.column_stack([np.ones_like(ts)] + [f(nu * ts) for nu in frequencies
                                              for f in (np.cos, np.sin)])
    c, *_ = np.linalg.lstsq(X, sol.y[0], rcond=None)
    return np.hypot(c[1::2], c[2::2])


def mixing(*args):
    out = run_forked("mixing", *args, check=True)
    return out.stdout


def test_converged_mixing_meets_the_reference_and_its_uncertainty_covers_the_simulation():
    """The README's case: ρ ≈ 0.08, converged; the drives' tones within 1e-3 (~ρ³) and the
    first-order ones within 2 % of the reference; each simulated tone within 3 of its own
    standard errors of the reference (the uncertainty is honest, and not vacuous: below 1e-6)."""
    args = ["--eps", "0.1", "--Q", "10", "--drive", "0.3@1.3", "--drive", "0.3@1.7"]
    data = json.loads(mixing(*args, "--json"))
    assert data["converged"] is True and 0.05 < data["expansion_parameter"] < 0.12
    tones = data["tones"]
    ref = reference_tones(0.1, 10.0, [(0.3, 1.3), (0.3, 1.7)], [t["frequency"] for t in tones])
    for t, r in zip(tones, ref, strict=True):
        assert abs(t["simulated"] - r) <= 3 * t["simulated_uncertainty"] + 1e-12, (t, r)
        assert 0 < t["simulated_uncertainty"] < 1e-6
        if t["order"] == 0:
            assert abs(t["predicted"] / r - 1) < 1e-3  # ~ρ³
        elif t["order"] == 1:
            assert abs(t["predicted"] / r - 1) < 0.02
    assert "warning" not in mixing(*args).splitlines()[1]


def test_mixing_outside_its_validity_says_so():
    """ε = 0.2, Q = 15, drives 0.4@0.8 and 0.3@1.9: ρ > 1, not converged, and rightly so: the
    predicted ω₁ tone is more than 30 % off the reference (1.358 against 0.843)."""
    args = ["--eps", "0.2", "--Q", "15", "--drive", "0.4@0.8", "--drive", "0.3@1.9"]
    data = json.loads(mixing(*args, "--json"))
    assert data["converged"] is False and data["expansion_parameter"] > 0.2
    assert "not converging" in data["reason"]
    k, w1 = next((k, t) for k, t in enumerate(data["tones"]) if t["combination"] == "w1")
    ref = reference_tones(0.2, 15.0, [(0.4, 0.8), (0.3, 1.9)],
                          [t["frequency"] for t in data["tones"]])[k]
    assert abs(ref - 0.8427) < 1e-3
    assert abs(w1["simulated"] - ref) <= 3 * w1["simulated_uncertainty"]
    assert abs(w1["predicted"] / ref - 1) > 0.3
    assert mixing(*args).splitlines()[1].startswith("warning: expansion parameter")


def test_sweep_jumps_are_where_the_amplitude_crosses_past_the_fold():
    """ε = 0.1, f = 0.3, Q = 30: the true lower fold is at 1.16379 (DOP853 shooting); sweeping
    down the small branch stays stable until it, so the jump lies below it, where the simulated
    amplitude crosses between the branches (≈ 1.1603), not at the start of the detecting window
    (1.16971 before: above the fold). Sweeping up, the jump lies above the upper fold."""
    data = json.loads(run_forked("response", "--eps", "0.1", "--force", "0.3", "--Q", "30",
                                 "--json", check=True).stdout)
    num = data["numerical"]
    lower, upper = num["folds"]
    assert abs(lower - 1.16379) < 1e-5
    step = num["sweep_resolution"]
    assert 1e-4 < step < 3e-4  # (2.17 − 0.5)/10⁴ per drive period
    assert lower - 0.005 < num["sweep_down_jump"] < lower
    assert abs(num["sweep_down_jump"] - 1.1603) < 0.002
    assert upper < num["sweep_up_jump"] < upper + 0.01


def test_a_softening_spring_over_its_barrier_escapes_and_is_reported_so():
    """ε = −0.1, f = 0.3, Q = 20: sweeping up, the resonance carries |q| past the barrier
    1/√0.1 = 3.16 near ω = 0.81 and the orbit leaves the well (before: "sweep up jumps at
    0.8016" with amplitudes of 1e214). Reported as an escape, never as a jump."""
    from lindstedt.numerics.integrate import sweep

    data = json.loads(run_forked("response", "--eps", "-0.1", "--force", "0.3", "--Q", "20",
                                 "--json", check=True).stdout)
    num = data["numerical"]
    assert num["sweep_up_jump"] is None and 0.7 < num["sweep_up_escape"] < 0.9
    run = sweep(-0.1, 0.3, 0.05, 0.5, 1.5)
    before = run.amplitude[run.omega < run.escape]
    assert np.all(np.isfinite(before)) and np.nanmax(before) <= 1 / np.sqrt(0.1)
    assert np.all(np.isnan(run.amplitude[run.omega > run.escape + 1e-3]))
    assert sweep(0.1, 0.3, 0.05, 0.5, 1.9).escape is None  # a hardening spring never escapes
    text = run_forked("response", "--eps", "-0.1", "--force", "0.3", "--Q", "20", check=True).stdout
    assert "escapes the well" in text and "jumps" not in text


def test_the_unstable_subharmonic_near_its_existence_boundary_is_found():
    """f = 7.8, ω = 1.05 (ε = 0.1): eq. 10.87's root − has a(f) = 0.266, 40 % from the true
    orbit's a₁ = 0.3727 — it was reported as "no orbit found". Reference: an even orbit
    (q̇(0) = q̇(T/2) = 0) found by brentq on DOP853 at rtol 1e-12, a₁ by quadrature, tr M by
    finite differences of the flow."""
    from scipy.optimize import brentq

    eps, f, w = 0.1, 7.8, 1.05
    period = 2 * np.pi / w

    def flow(y0, t_end):
        sol = solve_ivp(lambda t, y: [y[1], -y[0] - eps * y[0] ** 3 + f * np.cos(3 * w * t)],
                        (0, t_end), y0, method="DOP853", rtol=1e-12, atol=1e-13,
                        dense_output=True)
        return sol

    q0 = brentq(lambda q: flow([q, 0.0], period / 2).y[1, -1], -0.53, -0.49, xtol=1e-13)
    assert abs(q0 - (-0.50852167)) < 1e-7
    sol = flow([q0, 0.0], period)
    t = np.linspace(0, period, 4001)
    a1 = 2 / period * np.trapezoid(sol.sol(t)[0] * np.cos(w * t), t)
    h = 1e-6
    cols = [(flow(np.array([q0, 0.0]) + h * e, period).y[:, -1]
             - flow(np.array([q0, 0.0]) - h * e, period).y[:, -1]) / (2 * h)
            for e in np.eye(2)]
    trace = cols[0][0] + cols[1][1]
    assert trace > 2  # unstable (a real pair λ, 1/λ)
    data = json.loads(run_forked("subharmonic", "--eps", "0.1", "--force", "7.8", "--omega", "1.05",
                                 "--json", check=True).stdout)
    minus = next(s for s in data["solutions"] if s["root"] == "-")
    plus = next(s for s in data["solutions"] if s["root"] == "+")
    assert minus["numerical"] is not None, "the unstable orbit is missed"
    assert abs(minus["numerical"]["a1"] - a1) < 1e-6 and minus["numerical"]["stable"] is False
    assert abs(plus["numerical"]["a1"] - minus["numerical"]["a1"]) > 0.05  # two orbits


# --- escape from a softening spring's well, in shooting and in `driven` -------------------------

def _segment(y, t0, t1, eps, force, omega, damping, t_eval=None):
    """DOP853 (rtol 1e-12) on the equation and its variational equation from ``t0`` to ``t1``:
    the end state, the monodromy of the arc, the solution."""
    def rhs(t, z):
        k = -1.0 - 3.0 * eps * z[0] ** 2
        return [z[1], force * np.cos(omega * t) - damping * z[1] - z[0] - eps * z[0] ** 3,
                z[3], k * z[2] - damping * z[3], z[5], k * z[4] - damping * z[5]]

    sol = solve_ivp(rhs, (t0, t1), [y[0], y[1], 1.0, 0.0, 0.0, 1.0], method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=t_eval)
    end = sol.y[:, -1]
    return end[:2], np.array([[end[2], end[4]], [end[3], end[5]]]), sol


def multiple_shooting(y0, eps, force, omega, damping, segments=8):
    """A periodic orbit too unstable for single shooting (a Floquet multiplier ~1e8 turns the
    integrator's 1e-12 into 1e-4 over one period): Newton on the continuity of ``segments``
    DOP853 arcs, each amplifying errors by only the segments-th root.  ``(state, r,
    multipliers)``."""
    T = 2 * np.pi / omega
    ts = np.linspace(0, T, segments + 1)
    Y = [np.array(y0, float)]
    for i in range(segments - 1):
        Y.append(_segment(Y[-1], ts[i], ts[i + 1], eps, force, omega, damping)[0])
    Y = np.array(Y)
    for _ in range(30):
        F = np.zeros(2 * segments)
        J = np.zeros((2 * segments, 2 * segments))
        for i in range(segments):
            end, M, _ = _segment(Y[i], ts[i], ts[i + 1], eps, force, omega, damping)
            j = (i + 1) % segments
            F[2 * i:2 * i + 2] = end - Y[j]
            J[2 * i:2 * i + 2, 2 * i:2 * i + 2] += M
            J[2 * i:2 * i + 2, 2 * j:2 * j + 2] -= np.eye(2)
        step = np.linalg.solve(J, -F).reshape(segments, 2)
        Y = Y + step
        if np.max(np.abs(step)) < 1e-12 * (1 + np.max(np.abs(Y))):
            break
    else:
        raise AssertionError("multiple shooting did not converge")
    mono, c1, n = np.eye(2), 0j, 64
    for i in range(segments):
        t = ts[i] + (ts[i + 1] - ts[i]) * np.arange(n) / n
        _, M, sol = _segment(Y[i], ts[i], ts[i + 1], eps, force, omega, damping,
                             t_eval=np.append(t, ts[i + 1]))
        mono = M @ mono
        c1 += np.sum(sol.y[0, :-1] * np.exp(-1j * omega * t)) / (n * segments)
    return Y[0], float(2 * abs(c1)), np.linalg.eigvals(mono)


def escapes(y0, eps, force, omega, damping, t0=0.0, periods=1.0, far=1e3):
    """Whether DOP853 from ``y0`` at ``t0`` reaches ``|q| = far`` within ``periods`` drive
    periods (the softening spring's cubic force then runs it off to infinity)."""
    def rhs(t, z):
        return [z[1], force * np.cos(omega * t) - damping * z[1] - z[0] - eps * z[0] ** 3]

    def out(t, z):
        return abs(z[0]) - far
    out.terminal = True
    sol = solve_ivp(rhs, (t0, t0 + periods * 2 * np.pi / omega), list(y0), method="DOP853",
                    rtol=1e-12, atol=1e-12, events=out)
    return sol.status == 1


def test_shooting_reports_a_trajectory_past_the_escape_bound_as_escaping():
    """Every periodic orbit of the softening spring stays within |q| ≤ x, the root of
    |ε|x³ − x − |f| = 0 (numpy.roots here); from beyond it, moving outward, DOP853 runs off
    to infinity whatever the drive's phase — and shooting from there says it escapes, where it
    used to return nothing without a reason."""
    from lindstedt.numerics.integrate import escape_bound
    from lindstedt.numerics.shooting import shoot, shoot_explained

    eps, f, Q, w = -0.1, 0.3, 20.0, 0.8
    roots = np.roots([-eps, 0.0, -1.0, -f])
    x = max(r.real for r in roots if abs(r.imag) < 1e-12)
    assert abs(escape_bound(eps, f) - x) < 1e-14 * x and abs(escape_bound(eps, -f) - x) < 1e-14
    assert escape_bound(0.1, f) == np.inf
    start = np.array([1.001 * x, 0.0])
    for t0 in np.arange(4) * np.pi / (2 * w):
        assert escapes(start, eps, f, w, 1 / Q, t0)
        assert escapes(-start, eps, f, w, 1 / Q, t0)
    failure = shoot_explained(eps, f, w, 1 / Q, start)
    assert failure.escaped and "escapes the well" in failure.reason
    assert abs(failure.bound - x) < 1e-14 * x
    assert shoot(eps, f, w, 1 / Q, start) is None
    # a hardening spring has no well to leave: never an escape
    far = shoot_explained(0.1, f, w, 1 / Q, np.array([1e30, 0.0]))
    assert not getattr(far, "escaped", False)


def test_an_orbit_too_unstable_for_the_coarse_balance_guess_is_found():
    """ε = −0.1, f = 0.3, Q = 20, ω = 0.3: the orbit hugging the barrier has a Floquet
    multiplier 7.7e7; from the 8-harmonic balance (1e-5 off) its trajectory escapes within the
    period, and `driven` had it as a balance without an orbit. Against multiple shooting."""
    from lindstedt.analysis.driven import Drive
    from lindstedt.analysis.periodic import periodic_orbits

    eps, f, Q, w = -0.1, 0.3, 20.0, 0.3
    top = periodic_orbits(Drive(eps, f, w, Q)).orbits[0]
    assert top.orbit is not None and not top.orbit.stable and top.paired == "shot"
    state, r, lam = multiple_shooting(top.orbit.initial, eps, f, w, 1 / Q)
    assert np.max(np.abs(top.orbit.initial - state)) < 1e-8 * np.max(np.abs(state))
    assert abs(top.r - r) < 1e-8 * r
    got, ref = max(abs(top.orbit.multipliers)), max(abs(lam))
    assert ref > 1e7 and abs(got / ref - 1) < 1e-5


def test_driven_says_the_branch_escapes_the_well():
    """ε = −0.1, f = 0.3, Q = 20, ω = 0.2: the resonant branch leans over the barrier; the
    state of its harmonic balance runs off to infinity within a period (DOP853), and `driven`
    says it escapes the well (reason in `shooting_note`) instead of "no orbit found"; the
    in-well orbit beside it against DOP853 + Newton."""
    from test_branches import reference_orbit

    eps, f, Q, w = -0.1, 0.3, 20.0, 0.2
    args = ["driven", "--eps", str(eps), "--force", str(f), "--Q", str(Q), "--omega", str(w)]
    data = json.loads(run_forked(*args, "--json", check=True).stdout)
    *outer, small = data["branches"]
    assert outer  # the resonant branch (each root over the barrier: its own balance)
    for big in outer:
        assert big["numerical"] is None and big["escapes"] is True
        assert "escapes the well" in big["shooting_note"]
        hb = big["harmonic_balance"]
        y0 = (sum(hb["A"].values()), w * sum(int(n) * b for n, b in hb["B"].items()))
        assert escapes(y0, eps, f, w, 1 / Q)
        for key in ("A1", "r", "delta0", "mu_expansion", "mu_converged", "mu_note",
                    "harmonic_balance", "numerical", "seed", "first_order"):
            assert key in big
    assert small["escapes"] is False and small["shooting_note"] is None
    ref = reference_orbit(small["numerical"]["initial"], eps, f, w, 1 / Q)
    assert ref is not None and abs(ref[1] - small["numerical"]["r"]) < 1e-8
    assert ref[3] is small["numerical"]["stable"] is True
    # a root that stands for no branch (its balance converged onto another's) says why
    assert all(root["escapes"] for root in data["one_harmonic_roots"] if root["branch"] is None)
    text = run_forked(*args, check=True).stdout
    assert "(escapes the well)" in text and "no orbit found" not in text
