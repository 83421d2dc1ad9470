"""Spectral submanifolds (analysis.ssm, `lindstedt ssm`) against independent references: the
elliptic period of Duffing's oscillator, the exact L–P series of a normal mode, the exact
averaged flow of a damped oscillator, the closed-form response of a linear system, the full
system integrated from a point of the manifold, the dense eigenvalue problem."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
import scipy.sparse as sparse
from lindstedt.analysis import ssm as ssm_module
from lindstedt.analysis.ssm import ssm
from lindstedt.analysis.ssm_forced import BACKBONE_POINTS, forced_response, reduce
from lindstedt.cli import main
from lindstedt.derive.nnm import normal_mode
from lindstedt.derive.system import parse_system, read_model
from scipy.integrate import solve_ivp
from scipy.io import mmwrite
from scipy.optimize import brentq
from scipy.special import ellipk

KERSCHEN = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
PAIR = ("x1'' + 0.02*x1' + 2*x1 - x2 + x1**3 = f*cos(w*t); "
        "x2'' + 0.02*x2' + 2*x2 - x1 + 0.5*x2**2 = 0")


def _rho_at(model, amplitude: float, output: int = 0) -> float:
    """The ρ where the backbone's max |x_output| is ``amplitude``."""
    return brentq(lambda r: model.amplitude(np.array([r]), np.array([output]))[0, 0]
                  - amplitude, 1e-9, 0.9 * model.radius, xtol=1e-15)


@pytest.mark.parametrize("A", [0.1, 0.2])
def test_duffing_backbone_against_the_elliptic_period(A):
    """x'' + x + x³ = 0: ω(A) = π√(1 + A²)/(2K(m)), m = A²/(2(1 + A²)) (DLMF 22.13)."""
    model = ssm(parse_system("x'' + x + x**3 = 0", driven=True), 1, 17)
    m = A * A / (2 * (1 + A * A))
    exact = math.pi * math.sqrt(1 + A * A) / (2 * ellipk(m))
    assert abs(model.omega(_rho_at(model, A)) - exact) < 1e-11
    assert max(model.residual) < 1e-13
    assert abs(model.damping_ratio(0.3)) < 1e-15


@pytest.mark.parametrize("mode", [1, 2])
def test_undamped_backbone_equals_the_normal_mode_series(mode):
    """Undamped, the SSM is the Lyapunov subcenter manifold: its frequency against the
    physical amplitude max |x1| is nnm's exact backbone ω(A) (x1(0) = A, a turning point)."""
    system = parse_system(KERSCHEN)
    series = normal_mode(system, mode, 14)
    model = ssm(parse_system(KERSCHEN, driven=True), mode, 15)
    for A in (0.05, 0.15):
        omega, _, _ = series.evaluate(np.array([A]))
        assert abs(model.omega(_rho_at(model, A)) - float(omega[0])) < 1e-10


def test_damped_oscillator_against_the_averaged_flow():
    """x'' + εx' + x + εx³ = 0: the exact slow flow to order 2 (`slowflow`, van der Pol's
    r) against the SSM's ω and a at ρ = r: they differ by O(ε³) — the normal form's ρ and the
    averaged r are both the first harmonic's amplitude to O(ε²)."""
    out = []
    for eps in (0.1, 0.05, 0.025):
        text = f"x'' + {eps}*x' + x + {eps}*x**3 = 0"
        model = ssm(parse_system(text, driven=True), 1, 9)
        flow = _slowflow("x'' + x + eps*(x' + x**3) = 0")
        r = 0.5
        omega = 1 + eps * flow["phase"][0](r) + eps**2 * flow["phase"][1](r)
        decay = (eps * flow["radial"][0](r) + eps**2 * flow["radial"][1](r)) / r
        out.append((abs(model.omega(r) - omega), abs(model.decay(r) - decay)))
    for (w1, a1), (w2, a2) in itertools.pairwise(out):
        assert 6.5 < w1 / w2 < 9.5 and 6.5 < a1 / a2 < 9.5  # O(ε³)
    assert out[0][0] < 2e-5 and out[0][1] < 2e-6


def _slowflow(text: str) -> dict:
    """The exact slow flow of `lindstedt slowflow TEXT --order 2 --json`, as functions of r."""
    import contextlib
    import io

    import sympy as sp

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        assert main(["slowflow", text, "--order", "2", "--json"]) == 0
    data = json.loads(buffer.getvalue())
    r = sp.Symbol("r")
    return {key: [sp.lambdify(r, sp.sympify(e)) for e in data[key]]
            for key in ("radial", "phase")}


LINEAR = ("2*x1'' + x2'' + 0.05*x1' + 3*x1 - x2 = f*cos(w*t); "
          "x1'' + 3*x2'' + 0.03*x2' - x1 + 4*x2 - x3 = 0; x3'' + 0.01*x3' - x2 + 2*x3 = 0")


def test_linear_system_is_its_modal_plane_and_its_response_exact():
    """A linear system with a full mass matrix: γ = (λ), λ the dense eigenvalue, and the
    forced response at leading order is the exact |(K − Ω²M + iΩC)⁻¹F| of each coordinate."""
    system = parse_system(LINEAR, {"f": "1/10"}, driven=True)
    w = system.matrices
    M, C, K = w.mass.toarray(), w.damping.toarray(), w.stiffness.toarray()
    from scipy.linalg import eig

    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-np.linalg.solve(M, K),
                                                   -np.linalg.solve(M, C)]])
    lams = sorted((z for z in eig(A)[0] if z.imag > 0), key=lambda z: z.imag)
    for mode in (1, 2):
        model = ssm(system, mode, 5)
        assert abs(model.lam - lams[mode - 1]) < 1e-12
        assert all(g == 0 for g in model.gamma[1:])
        assert math.isinf(model.radius)
    model = ssm(system, 1, 5)
    omegas = np.linspace(0.6 * model.lam.imag, 1.4 * model.lam.imag, 7)
    response = forced_response(model, omegas, np.arange(3))
    assert len(response.states) == len(omegas)
    for state in response.states:
        exact = np.abs(np.linalg.solve(K - state.omega**2 * M + 1j * state.omega * C,
                                       w.drive))
        assert np.max(np.abs(state.amplitude - exact)) < 1e-12 * np.max(exact)
        assert state.stable


def test_free_motion_stays_on_the_manifold():
    """The full system integrated from a point of the SSM of a damped pair with quadratic
    and cubic terms follows the reduced dynamics: x(t) = W(p(t)); the error falls with K."""
    system = parse_system(PAIR.replace("f*cos(w*t)", "0"), driven=True)
    w = system.matrices
    Mi = np.linalg.inv(w.mass.toarray())
    C, K = w.damping.toarray(), w.stiffness.toarray()

    def field(t, y):
        x, v = y[:2], y[2:]
        return np.concatenate([v, -Mi @ (C @ v + K @ x + w.force(x, v))])

    errors = []
    for order in (3, 5, 7):
        model = ssm(system, 1, order)
        rho0, times = 0.25, np.linspace(0, 20, 41)
        def reduced(t, z, model=model):
            return [z[0] * model.decay(z[0]), model.omega(z[0])]

        p = solve_ivp(reduced, (0, 20), [rho0, 0.0], t_eval=times, rtol=1e-12, atol=1e-14).y
        predicted = np.array([np.real(np.sum(model.harmonics(r, np.arange(2), th)[0]
                                             .T * 1, axis=1)) for r, th in p.T])
        y0 = np.concatenate([predicted[0], _velocity(model, rho0)])
        full = solve_ivp(field, (0, 20), y0, t_eval=times, rtol=1e-12, atol=1e-14,
                         method="DOP853").y[:2].T
        errors.append(np.max(np.abs(full - predicted)))
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 2e-5


def _velocity(model, rho: float) -> np.ndarray:
    """``V(ρ, ρ)`` at θ = 0: x' on the manifold."""
    return np.real(sum(rho**k * model.V[k].sum(axis=0) for k in range(1, model.order + 1)))


def test_lanczos_route_equals_the_dense_one(monkeypatch, tmp_path):
    """A graded chain of 240 masses (past DENSE_MODES): the mode from shift-invert Lanczos
    and Newton equals the dense eigenvalue problem's, and so does every γ."""
    n = 240
    k = 1 + 2 * np.arange(n + 1) / n
    K = sparse.diags([k[:-1] + k[1:], -k[1:-1], -k[1:-1]], [0, 1, -1], format="csr")
    M = sparse.diags(1 + np.arange(n) / n, format="csr")
    folder = _model_folder(tmp_path, M, K, 0.002 * K + 0.01 * M,
                           [f"{i} {i} {i} {i} 0.5" for i in range(n)], None)
    system = read_model(folder)
    lanczos = ssm(system, 1, 5)
    monkeypatch.setattr(ssm_module, "DENSE_MODES", 10**4)
    dense = ssm(system, 1, 5)
    assert "Lanczos" in lanczos.linear.checked and "dense" in dense.linear.checked
    assert abs(lanczos.lam - dense.lam) < 1e-12 * abs(dense.lam)
    for a, b in zip(lanczos.gamma, dense.gamma, strict=True):
        assert abs(a - b) < 1e-9 * abs(b)


@pytest.mark.parametrize("turn", [-1.0, 1j, np.exp(2.5j)])
def test_the_mode_shape_does_not_follow_lapacks_orientation(monkeypatch, turn):
    """A symmetric pair's lower mode is (1, −1)/(2√2): its two components are equal in size and
    differ by rounding that LAPACK's kernels do not share across machines.  Its eigenvectors
    turned by −1, i or any phase, and the largest component made larger or smaller by one
    rounding, give the same shape: the first of the largest components real and positive."""
    system = parse_system("x1'' + 5*x1/2 + 3*x2/2 + x1**2 = 0; x2'' + 3*x1/2 + 5*x2/2 = 0")
    eig = np.linalg.eig
    for nudge in (1 - 2**-52, 1 + 2**-52):
        def turned(A, nudge=nudge):
            lams, vecs = eig(A)
            vecs = vecs * turn
            vecs[1] *= nudge  # x2's component a rounding larger or smaller than x1's
            return lams, vecs

        monkeypatch.setattr(np.linalg, "eig", turned)
        shape = ssm_module.linear_mode(system.matrices, 1).shape
        assert np.max(np.abs(shape - np.array([1, -1]) / (2 * math.sqrt(2)))) < 1e-15
    assert ssm_module.leading(np.array([1 - 2**-52, -1.0, 0.5])) == 0
    assert ssm_module.leading(np.array([0.5, -1.0, 1 - 2**-52])) == 1


def _model_folder(folder, M, K, C, lines, drive):
    """A model folder as a finite-element code writes it."""
    mmwrite(folder / "M.mtx", sparse.coo_matrix(M))
    mmwrite(folder / "K.mtx", sparse.coo_matrix(K))
    if C is not None:
        mmwrite(folder / "C.mtx", sparse.coo_matrix(C))
    (folder / "nonlinear.txt").write_text("\n".join(lines) + "\n")
    if drive is not None:
        (folder / "drive.txt").write_text("\n".join(f"{i} {F!r}" for i, F in drive) + "\n")
    return folder


def _json(argv, capsys) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_model_folder_equals_the_text(tmp_path, capsys):
    """The pair written as a model folder (M, K, C, nonlinear.txt, drive.txt) gives the JSON
    of the pair written as text, outputs named x0, x1 by index."""
    text = _json(["ssm", PAIR, "--param", "f=1/100", "--order", "7", "--omega",
                  "0.95:1.05:21", "--json"], capsys)
    system = parse_system(PAIR, {"f": "1/100"}, driven=True)
    w = system.matrices
    folder = _model_folder(tmp_path, w.mass, w.stiffness, w.damping,
                           ["0 0 0 0 1.0", "1 1 1 0.5"], [(0, 0.01)])
    model = _json(["ssm", "--model", str(folder), "--order", "7", "--omega", "0.95:1.05:21",
                   "--output", "0,1", "--json"], capsys)
    assert list(model["outputs"]) == ["x0", "x1"]
    for key in ("lambda", "gamma"):
        assert np.allclose(model[key], text[key], rtol=1e-12, atol=1e-15)
    a = [[s["amplitude"]["x1"], s["amplitude"]["x2"]] for s in text["frc"]]
    b = [[s["amplitude"]["x0"], s["amplitude"]["x1"]] for s in model["frc"]]
    assert np.allclose(a, b, rtol=1e-10)


def test_contract_keys(capsys):
    data = _json(["ssm", PAIR, "--param", "f=1/100", "--order", "5", "--omega",
                  "0.9:1.1:50", "--json"], capsys)
    assert data["kind"] == "ssm" and data["mode"] == 1
    assert len(data["lambda"]) == 2 and all(len(g) == 2 for g in data["gamma"])
    assert set(data["backbone"][0]) >= {"rho", "omega", "damping_ratio", "amplitude"}
    assert set(data["frc"][0]) >= {"omega", "amplitude", "stable"}
    assert set(data["frc"][0]["amplitude"]) == {"x1", "x2"}
    assert abs(data["backbone"][0]["damping_ratio"] - data["linear"]["damping_ratio"]) < 1e-15


@pytest.mark.parametrize("argv, message", [
    (["ssm", "x'' + 0.1*x' + x + x**3 = 0", "--omega", "0.5:1.5"], "not driven"),
    (["ssm", "x'' + x + x**3 = 0", "--model", "."], "one of them"),
    (["ssm", "x1'' + x1 + x1*x2 = 0; x2'' + 4*x2 = 0", "--output", "5"], "outside 0..1"),
    (["ssm", "x1'' + x1 + x1*x2 = 0; x2'' + 4*x2 = 0", "--output", "y"], "neither"),
    (["ssm", "x'' + x + x**3 = 0", "--mode", "2"], "1 oscillating mode"),
    (["ssm", "x1'' + x1 + x1**3 = 0; x2'' + 9*x2 + x1**3 = 0", "--order", "3"],
     "internal resonance"),
    (["ssm", "x'' + x + x**3 = 0", "--rho-max", "50", "--order", "9"], "radius"),
    (["ssm", "x'' + x + x**3 = 0", "--order", "99"], "order ≤ 41"),
])
def test_refusals_are_one_line(argv, message, capsys):
    try:
        status = main(argv)
    except SystemExit as exc:  # argparse's own refusal
        status = exc.code
    assert status == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_near_resonance_is_reported_with_its_divisor(capsys):
    """ω₂ = 3.03 ω₁: the monomial p₁³ of order 3 is near mode 2 (divisor 0.03)."""
    data = _json(["ssm", "x1'' + 0.01*x1' + x1 + x1**3 + x1*x2**2 = 0; "
                  "x2'' + 0.01*x2' + 9.1809*x2 + x1**3 = 0", "--order", "3", "--json"], capsys)
    near = data["near_resonances"]
    assert any(q["monomial"] == [3, 0] and abs(q["divisor"] - 0.03) < 3e-3 for q in near)


def test_table_csv_and_plot(tmp_path, capsys):
    csv, png = tmp_path / "s.csv", tmp_path / "s.png"
    assert main(["ssm", PAIR, "--param", "f=1/100", "--order", "5", "--omega", "0.9:1.1:40",
                 "--csv", str(csv), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "peak of x1" in out and "backbone" in out
    rows = csv.read_text().splitlines()
    assert rows[0].startswith("frc [") and len(rows) == 1 + BACKBONE_POINTS + 40
    assert png.stat().st_size > 10_000


def test_reduce_defaults_to_every_coordinate_and_the_linear_span():
    red = reduce(parse_system(PAIR, {"f": "1/100"}, driven=True), 1, 3, points=11)
    assert red.names == ("x1", "x2")
    omegas = sorted({s.omega for s in red.response.states})
    assert abs(omegas[0] - 0.8 * abs(red.model.lam)) < 1e-12


SHOT = [
    # a cubic pair, weak damping (ζ = 0.005), the peak 3.5 % above the linear resonance
    ("x1'' + 0.01*x1' + 2*x1 - x2 + x1**3 = f*cos(w*t); x2'' + 0.01*x2' + 2*x2 - x1 = 0",
     "1/100", 0.95, 1.1, 9),
    # quadratic and cubic, moderate damping (ζ = 0.05), the peak 2 % above it
    ("x1'' + 0.1*x1' + 2*x1 - x2 + 0.5*x1**2 + x1**3 = f*cos(w*t); "
     "x2'' + 0.1*x2' + 2*x2 - x1 + 0.3*x2**2 = 0", "1/10", 0.85, 1.15, 7),
]


@pytest.mark.parametrize("text, f, lo, hi, order", SHOT)
def test_forced_peak_against_full_order_shooting(text, f, lo, hi, order):
    """The forced response's peak (max |x1| over a period) from the reduced model against
    full-order shooting through the fold (tests/ssm_reference.py, judged by its residual):
    1e-3 relative at a forcing that moves the peak ≥ 2 % off the linear resonance, the error
    falling from order 3."""
    from ssm_reference import peak as shot_peak
    from ssm_reference import terms_force

    system = parse_system(text, {"f": f}, driven=True)
    w = system.matrices
    table = w.force
    terms = [(int(e), [int(k) for k in fa if k >= 0], float(c))
             for e, fa, c in zip(table.equation, table.factors, table.coefficient, strict=True)]
    omega, amplitude = shot_peak(w.mass.toarray(), w.damping.toarray(), w.stiffness.toarray(),
                                 terms_force(2, terms), w.drive, lo, hi, 0)
    errors = []
    for k in (3, order):
        model = ssm(system, 1, k)
        top = forced_response(model, np.linspace(lo, hi, 200), np.arange(2)).peaks[0]
        errors.append(abs(top.amplitude / amplitude - 1))
    assert abs(omega / abs(model.lam) - 1) >= 0.02
    assert errors[1] < 1e-3 < errors[0]
    assert abs(top.omega - omega) < 1e-3


def test_a_curve_still_rising_at_the_range_end_has_no_peak():
    """x'' + 0.02x' + x + x³ = 0.01 cos ωt peaks near ω = 1.08 (the hardening backbone at
    the peak's amplitude, 0.47): over [0.9, 1.05] the curve leaves the range still rising and
    no peak is reported (it was the range's end); over [0.9, 1.2] the peak lies on the
    backbone, ω(ρ) at the peak's ρ."""
    duffing = parse_system("x'' + 0.02*x' + x + x**3 = f*cos(w*t)", {"f": "1/100"}, driven=True)
    assert reduce(duffing, mode=1, order=9, span=(0.9, 1.05)).response.peaks[0] is None
    red = reduce(duffing, mode=1, order=9, span=(0.9, 1.2))
    top = red.response.peaks[0]
    assert 1.05 < top.omega < 1.2
    assert abs(top.omega - float(red.model.omega(top.rho))) < 1e-3 * top.omega


def test_a_narrow_range_about_the_peak_finds_the_same_peak():
    """A graded pair with a cubic spring (peak +2.6 % above ω₁): the peak from ±0.3 % about
    it equals the one from ±10 % (it was None at K = 9: one geometric probe between the
    states found fell where the curve's fixed point fails), and an empty range has none."""
    pair = parse_system("x1'' + 2789/100000*x1' + 11/4*x1 - 7/4*x2 + 4*x1**3 = f*cos(w*t); "
                        "x2'' + 2789/100000*x2' + 23/4*x2 - 7/4*x1 = 0", {"f": "1/100"},
                        driven=True)
    model = ssm(pair, 1, 9)
    outputs = np.array([0])
    wide = forced_response(model, np.linspace(1.3, 1.6, 500), outputs).peaks[0]
    narrow = forced_response(model, np.linspace(wide.omega * 0.997, wide.omega * 1.003, 500),
                             outputs).peaks[0]
    assert narrow is not None
    assert abs(narrow.amplitude - wide.amplitude) < 1e-8 * wide.amplitude
    assert abs(narrow.omega - wide.omega) < 1e-7 * wide.omega
    assert forced_response(model, np.empty(0), outputs).peaks == (None,)
