"""``examples/beam_model.py``: the clamped–clamped von Kármán beam it writes, against routes
of its own — Euler–Bernoulli's frequencies (``cos βL cosh βL = 1``), the exact discrete
axial frequencies of linear elements, the strain and kinetic energies integrated by Gauss
quadrature of the cubic fitted to each element's nodal values (finite differences of the
nonlinear part give ``f``), ``read_model`` and ``scipy.linalg.eigh`` of the dense matrices —
and the folder's form: the same bytes every run, each monomial once per equation."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.optimize import brentq

PATH = Path(__file__).resolve().parent.parent / "examples" / "beam_model.py"


@pytest.fixture(scope="module")
def bm():
    spec = importlib.util.spec_from_file_location("beam_model", PATH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["beam_model"] = module  # dataclasses look their module up
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        del sys.modules["beam_model"]


# A beam with nothing equal to 1, so that a wrong power of h or of a material constant shows.
ODD = {"length": 1.3, "width": 0.7, "thickness": 0.2, "young": 7.0, "density": 3.0}


def read_terms(path: Path) -> list[tuple[int, tuple[int, ...], float]]:
    """``nonlinear.txt`` read here, not by the package: ``(i, factors, c)``."""
    out = []
    for line in path.read_text().splitlines():
        fields = line.split("#")[0].split()
        if fields:
            out.append((int(fields[0]), tuple(int(k) for k in fields[1:-1]), float(fields[-1])))
    return out


def evaluate(terms, x: np.ndarray, degree: int) -> np.ndarray:
    """The part of ``f(x)`` of one degree."""
    f = np.zeros_like(x)
    for i, factors, c in terms:
        if len(factors) == degree:
            f[i] += c * np.prod(x[list(factors)])
    return f


def clamped_frequencies(beam, count: int) -> np.ndarray:
    """Euler–Bernoulli's clamped–clamped ``ω_k = (β_k L)² / L² · √(EI/ρA)``."""
    roots = [brentq(lambda z: math.cos(z) * math.cosh(z) - 1, (k + 0.5) * math.pi - 1,
                    (k + 0.5) * math.pi + 1, xtol=1e-15) for k in range(1, count + 1)]
    E, rho, b, t, L = beam.young, beam.density, beam.width, beam.thickness, beam.length
    return np.array(roots) ** 2 / L**2 * math.sqrt(E * b * t**3 / 12 / (rho * b * t))


# --- energies by quadrature, nodal values → polynomials fitted per element ----------------


def element_fields(beam, x: np.ndarray):
    """Per element, at Gauss points: ``u``, ``u'``, ``w``, ``w'``, ``w''`` and the weights
    (``dx`` included).  The state ``x`` is put back among the clamped nodes (node ``k`` at
    DOFs ``3k, 3k+1, 3k+2`` of the full vector: ``u, w, w'``), and each element's cubic
    ``w(s)`` is found from its four end conditions by a linear solve."""
    N, L = beam.elements, beam.length
    h = L / N
    full = np.zeros(3 * (N + 1))
    full[3:-3] = x
    nodes = full.reshape(N + 1, 3)
    gauss, weights = np.polynomial.legendre.leggauss(6)
    s = h * (gauss + 1) / 2  # points in an element, s ∈ (0, h)
    conditions = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, h, h**2, h**3],
                           [0, 1, 2 * h, 3 * h**2]])  # w(0), w'(0), w(h), w'(h) of Σ a_k s^k
    ends = np.column_stack([nodes[:-1, 1], nodes[:-1, 2], nodes[1:, 1], nodes[1:, 2]])
    a = np.linalg.solve(conditions, ends.T).T  # (N, 4)
    powers = np.arange(4)
    w = a @ (s[None, :] ** powers[:, None])
    dw = a[:, 1:] @ (powers[1:, None] * s[None, :] ** (powers[1:, None] - 1))
    d2w = a[:, 2:] @ (np.array([2, 6])[:, None] * s[None, :] ** np.array([0, 1])[:, None])
    u = nodes[:-1, 0:1] + (nodes[1:, 0:1] - nodes[:-1, 0:1]) * s / h
    du = np.broadcast_to((nodes[1:, 0:1] - nodes[:-1, 0:1]) / h, u.shape)
    return u, du, w, dw, d2w, weights * h / 2


def section(beam) -> tuple[float, float, float]:
    A = beam.width * beam.thickness
    return beam.young * A, beam.young * beam.width * beam.thickness**3 / 12, beam.density * A


def nonlinear_energy(beam, x: np.ndarray) -> float:
    """``½ ∫ EA (ε² − u'²) dx`` with ``ε = u' + ½ w'²``."""
    _, du, _, dw, _, dx = element_fields(beam, x)
    EA = section(beam)[0]
    return float(np.sum(0.5 * EA * ((du + dw**2 / 2) ** 2 - du**2) * dx))


def linear_energy(beam, x: np.ndarray) -> float:
    """``½ ∫ (EA u'² + EI w''²) dx``."""
    _, du, _, _, d2w, dx = element_fields(beam, x)
    EA, EI, _ = section(beam)
    return float(np.sum(0.5 * (EA * du**2 + EI * d2w**2) * dx))


def kinetic_form(beam, x: np.ndarray) -> float:
    """``∫ ρA (u² + w²) dx`` (``xᵀ M x``)."""
    u, _, w, _, _, dx = element_fields(beam, x)
    return float(np.sum(section(beam)[2] * (u**2 + w**2) * dx))


def gradient(energy, x: np.ndarray, step: float) -> np.ndarray:
    """Central differences, Richardson-extrapolated: exact for a quartic up to rounding."""

    def central(d: float) -> np.ndarray:
        g = np.empty_like(x)
        for k in range(len(x)):
            e = np.zeros_like(x)
            e[k] = d
            g[k] = (energy(x + e) - energy(x - e)) / (2 * d)
        return g

    return (4 * central(step / 2) - central(step)) / 3


# --- the tests ------------------------------------------------------------------------------


def test_bending_frequencies_are_euler_bernoulli(bm):
    """The lowest frequencies of the assembled ``(M, K)`` (dense, every mode) are the
    clamped–clamped beam's: 1e-5 at 40 elements, the error falling as ``h⁴`` (×16 less from
    20 to 40 elements); the model's own (sparse, printed) agree with the dense ones."""
    errors = {}
    for N in (20, 40):
        model = bm.assemble(bm.Beam(elements=N))
        lam = eigh(model.stiffness.toarray(), model.mass.toarray(), eigvals_only=True)
        omega = np.sqrt(lam[:3])
        errors[N] = omega / clamped_frequencies(model.beam, 3) - 1
        assert np.allclose(model.bending[:3], omega, rtol=1e-9, atol=0)
    assert np.all(np.abs(errors[40]) < 1e-5), errors[40]
    assert np.all(errors[40] > 0)  # a conforming element's frequencies lie above
    assert np.all(errors[20] / errors[40] > 14), errors


def test_axial_frequencies_are_the_discrete_ones(bm):
    """The axial block (every third DOF) has linear elements' exact discrete frequencies
    ``ω_j² = 6 E / (ρ h²) · (1 − cos(jπ/N)) / (2 + cos(jπ/N))``."""
    beam = bm.Beam(elements=12, **ODD)
    model = bm.assemble(beam)
    axial = np.arange(0, beam.size, 3)
    K = model.stiffness.toarray()[np.ix_(axial, axial)]
    M = model.mass.toarray()[np.ix_(axial, axial)]
    lam = eigh(K, M, eigvals_only=True)
    j = np.arange(1, beam.elements) * math.pi / beam.elements
    h = beam.length / beam.elements
    exact = 6 * beam.young / (beam.density * h**2) * (1 - np.cos(j)) / (2 + np.cos(j))
    assert np.allclose(lam, exact, rtol=1e-12, atol=0)
    assert np.allclose(model.axial, np.sqrt(exact[:5]), rtol=1e-12, atol=0)
    coupling = model.stiffness.toarray()[np.ix_(axial, np.setdiff1d(np.arange(beam.size),
                                                                    axial))]
    assert not coupling.any()  # linearly, axial and bending motions are apart


def test_force_is_the_energy_gradient(bm, tmp_path: Path):
    """``f(x)`` as ``nonlinear.txt`` writes it is the gradient of the strain energy's
    nonlinear part, integrated here by quadrature, at a random state: its quadratic and its
    cubic part apart (``f₂ = (g(x) + g(−x))/2``, ``f₃ = (g(x) − g(−x))/2``), to 1e-8; and
    ``K x``, ``xᵀ M x`` are the linear energy's gradient and the kinetic form."""
    beam = bm.Beam(elements=6, **ODD)
    bm.write_folder(bm.assemble(beam), tmp_path)
    terms = read_terms(tmp_path / "nonlinear.txt")
    x = np.random.default_rng(7).normal(scale=0.3, size=beam.size)

    def energy(y: np.ndarray) -> float:
        return nonlinear_energy(beam, y)

    g_plus, g_minus = gradient(energy, x, 1e-3), gradient(energy, -x, 1e-3)
    for degree, part in ((2, (g_plus + g_minus) / 2), (3, (g_plus - g_minus) / 2)):
        f = evaluate(terms, x, degree)
        assert np.max(np.abs(f - part)) < 1e-8 * np.max(np.abs(part)), degree

    model = bm.assemble(beam)
    Kx = model.stiffness @ x
    linear = gradient(lambda y: linear_energy(beam, y), x, 1e-3)
    assert np.max(np.abs(Kx - linear)) < 1e-8 * np.max(np.abs(linear))
    assert math.isclose(x @ (model.mass @ x), kinetic_form(beam, x), rel_tol=1e-12)


def test_read_model_agrees(bm, tmp_path: Path):
    """``read_model`` reads the folder as written (matrices, force, drive) and its
    ``frequencies(3)`` — shift-invert Lanczos at this size, just above ``DENSE_MODES`` — are
    ``eigh``'s of the dense ``M``, ``K`` (to 1e-8: the dense generalized problem, axial
    stiffness included, is itself good to a few 1e-9 here)."""
    from lindstedt.derive.system import DENSE_MODES, read_model

    beam = bm.Beam(elements=68)
    assert beam.size > DENSE_MODES
    model = bm.assemble(beam, zeta=0.02, force=0.5)
    bm.write_folder(model, tmp_path)
    system = read_model(tmp_path)
    read = system.matrices
    assert read.size == beam.size
    for a, b in ((read.mass, model.mass), (read.stiffness, model.stiffness),
                 (read.damping, model.damping)):
        assert abs(a - b).max() == 0  # shortest round-trip digits: exactly the same
    expected = np.zeros(beam.size)
    expected[beam.midspan] = 0.5
    assert np.array_equal(read.drive, expected)
    x = np.random.default_rng(3).normal(scale=1e-3, size=beam.size)
    terms = read_terms(tmp_path / "nonlinear.txt")
    mine = evaluate(terms, x, 2) + evaluate(terms, x, 3)
    assert np.allclose(read.force(x), mine, rtol=1e-13, atol=1e-13 * np.abs(mine).max())
    lam = eigh(model.stiffness.toarray(), model.mass.toarray(), eigvals_only=True)
    assert np.allclose(read.frequencies(3), np.sqrt(lam[:3]), rtol=1e-8, atol=0)


def test_rayleigh_damping_ratio(bm):
    """``C = αM + βK`` damps bending modes 1 and 2 by exactly ``ζ``, mode 3 more."""
    model = bm.assemble(bm.Beam(elements=16, **ODD), zeta=0.03)
    M, K, C = (A.toarray() for A in (model.mass, model.stiffness, model.damping))
    lam, phi = eigh(K, M)
    omega = np.sqrt(lam)
    zeta = np.einsum("ik,ij,jk->k", phi, C, phi) / (2 * omega)  # φᵀMφ = 1
    assert np.allclose(zeta[:2], 0.03, rtol=1e-10)
    assert zeta[2] > 0.03


def test_folder_form(bm, tmp_path: Path, capsys):
    """The command writes the same bytes twice; each ``(i, factors)`` once, factors
    ascending, within the element's reach (three nodes' DOFs); it prints the mid-span DOF
    and the ssm command; an odd number of elements is refused."""
    for name in ("a", "b"):
        assert bm.main([str(tmp_path / name), "--elements", "10", "--force", "0.25"]) == 0
    out = capsys.readouterr().out
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files == ["C.mtx", "K.mtx", "M.mtx", "drive.txt", "nonlinear.txt"]
    for name in files:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    midspan = 3 * (5 - 1) + 1
    assert f"DOF {midspan}" in out
    assert f"--mode 1 --order 7 --output {midspan}" in out
    assert read_terms(tmp_path / "a" / "drive.txt") == [(midspan, (), 0.25)]

    terms = read_terms(tmp_path / "a" / "nonlinear.txt")
    keys = [(i, f) for i, f, _ in terms]
    assert len(set(keys)) == len(keys)
    assert all(list(f) == sorted(f) and len(f) in (2, 3) and c != 0 for _, f, c in terms)
    assert all(max(i, *f) // 3 - min(i, *f) // 3 <= 1 for i, f in keys)  # one element
    assert {len(f) for _, f, _ in terms} == {2, 3}
    assert (tmp_path / "a" / "nonlinear.txt").read_text().isascii()

    assert bm.main([str(tmp_path / "c"), "--elements", "9"]) == 2
    assert not (tmp_path / "c").exists()


def test_ssm_backbone_against_shooting(bm, tmp_path: Path):
    """The SSM backbone of the undamped beam (``--zeta 0``: ``C = 0``; ``lindstedt ssm
    --model``'s route, ``read_model`` then ``analysis.ssm``) against the conservative beam's
    periodic orbits, every coordinate kept: ``tests/ssm_reference.py``'s ``backbone``
    (half-period shooting with the period unknown, DOP853, each orbit judged by a whole
    period's residual ``|(x(T) − x(0), v(T)/ω)| / |x(0)|`` ≤ 1e-10).  Four elements and a
    50 mm thick section: the axial modes lie 35 times above the lowest, not 870 times as in
    the 2 mm strip, so an adaptive integrator shoots it in seconds — and the backbone
    in ``w/t`` is the strip's (the errors below are the 4-element 2 mm strip's at the same
    ``w/t`` to four digits).  At ``w(L/2) = 0.15 t`` and ``0.3 t`` (the frequency up 0.9 % and
    3.4 %) the SSM's ω at the same mid-span amplitude is within 8e-8 and 2.1e-5 at K = 7,
    2.4e-9 and 2.5e-6 at K = 9 (``benchmarks/beam_backbone.py``'s table has the 8-element
    strip, K = 3 … 9): checked within four times those, and falling with K."""
    from lindstedt.analysis.ssm import ssm
    from lindstedt.derive.system import read_model
    from scipy.optimize import brentq
    from ssm_reference import backbone

    beam = bm.Beam(elements=4, thickness=0.05)
    model = bm.assemble(beam, zeta=0.0)
    bm.write_folder(model, tmp_path)
    system = read_model(tmp_path)
    assert system.matrices.damping is None or not system.matrices.damping.count_nonzero()
    out = beam.midspan
    amplitudes = [0.15 * beam.thickness, 0.3 * beam.thickness]
    equation, factors, coefficient = model.terms
    terms = [(i, [k for k in f if k >= 0], c) for i, f, c in
             zip(equation.tolist(), factors.tolist(), coefficient.tolist(), strict=True)]
    orbits = backbone(model.mass.toarray(), model.stiffness.toarray(), terms, out, amplitudes,
                      tol=1e-10, method="DOP853")
    w0 = model.bending[0]
    assert orbits[0].omega / w0 - 1 > 0.008 and orbits[1].omega / w0 - 1 > 0.03
    errors = {}

    def gap(rho: float, red, A: float) -> float:  # the SSM's amplitude at rho, less A
        return float(red.amplitude(np.array([rho]), np.array([out]))[0, 0]) - A

    for K in (7, 9):
        red = ssm(system, 1, K)
        for A, orbit in zip(amplitudes, orbits, strict=True):
            assert orbit.residual <= 1e-10
            assert math.isclose(orbit.amplitude[out], A, rel_tol=1e-9)  # the peak is at t = 0
            assert gap(0.5 * red.radius, red, A) > 0  # A lies well inside the radius
            rho = brentq(gap, 0.0, 0.5 * red.radius, args=(red, A), xtol=1e-16, rtol=1e-14)
            errors[K, A] = abs(red.omega(np.array([rho]))[0] / orbit.omega - 1)
    small, large = amplitudes
    assert errors[7, small] < 3.2e-7 and errors[7, large] < 8.4e-5, errors
    assert errors[9, small] < 1e-8 and errors[9, large] < 1e-5, errors
    assert errors[9, small] < errors[7, small] / 5 and errors[9, large] < errors[7, large] / 5
