"""A full (symmetric positive definite) mass matrix: the system as written, ``M x'' + K x + f =
0``, against the same system inverted by hand (exact series, equal), and its emitted modules
against shooting whose right-hand side solves ``M x'' = −(K x + f)`` in NumPy (another route
than the parser's exact ``M⁻¹``); the refusals of a mass that is not one."""

from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest
import sympy as sp
from commands import run
from lindstedt.derive.nnm import normal_mode
from lindstedt.derive.system import parse_system
from scipy.integrate import solve_ivp
from scipy.optimize import root

FULL = "2*x1'' + x2'' + 3*x1 - x2 + x1**3 = 0; x1'' + 2*x2'' - x1 + 2*x2 = 0"
# NOTE: M = [[2, 1], [1, 2]], M⁻¹ = [[2, −1], [−1, 2]]/3 by hand: x'' = −M⁻¹(Kx + f) is
INVERTED = ("x1'' + 7/3*x1 - 4/3*x2 + 2/3*x1**3 = 0; "
            "x2'' - 5/3*x1 + 5/3*x2 - 1/3*x1**3 = 0")
# and det(K − λM) = 3λ² − 12λ + 5: λ = 2 ∓ √21/3.

DECIMAL = ("1.2*x1'' + 0.3*x2'' + 2.5*x1 - 1.1*x2 + 0.4*x1**3 = 0; "
           "0.3*x1'' + 0.8*x2'' - 1.1*x1 + 1.7*x2 + 0.2*x2**3 = 0")
MASS = np.array([[1.2, 0.3], [0.3, 0.8]])
STIFFNESS = np.array([[2.5, -1.1], [-1.1, 1.7]])
RESIDUAL = 1e-11


def _force(x: np.ndarray) -> np.ndarray:
    return np.array([0.4 * x[0] ** 3, 0.2 * x[1] ** 3])


@pytest.mark.parametrize("which", [1, 2])
def test_full_mass_series_equals_the_hand_inverted_system_exactly(which):
    full, inverted = (normal_mode(parse_system(t), which, 8) for t in (FULL, INVERTED))
    assert sp.simplify(full.omega0**2 - (2 + (-1) ** which * sp.sqrt(21) / 3)) == 0
    assert [sp.simplify(a - b) for a, b in zip(full.omega(), inverted.omega(), strict=True)] \
        == [0] * 9
    for i in range(2):
        assert [{n: sp.simplify(c - inverted.coordinate(i)[j][n]) for n, c in order.items()}
                for j, order in enumerate(full.coordinate(i))] == \
            [dict.fromkeys(order, 0) for order in inverted.coordinate(i)]


def test_mass_matrix_is_kept_and_the_lowered_form_is_m_inverse_k():
    s = parse_system(FULL)
    assert s.mass == sp.Matrix([[2, 1], [1, 2]])
    assert s.stiffness == sp.Matrix([[sp.Rational(7, 3), sp.Rational(-4, 3)],
                                     [sp.Rational(-5, 3), sp.Rational(5, 3)]])
    x1 = s.coordinates[0]
    assert s.force == (2 * x1**3 / 3, -x1**3 / 3)


def _shoot(A: float, x2: float, half: float) -> tuple[float, float]:
    """The orbit through x1(0) = A, every velocity zero, by DOP853 on M x'' = −(K x + f)."""
    def rhs(t, z):
        return np.concatenate([z[2:], np.linalg.solve(MASS, -(STIFFNESS @ z[:2] + _force(z[:2])))])

    def at_half(u):
        sol = solve_ivp(rhs, (0, u[1]), [A, u[0], 0, 0], method="DOP853", rtol=1e-13,
                        atol=1e-15)
        return sol.y[2:, -1]

    out = root(at_half, [x2, half], method="hybr", tol=1e-14)
    residual = np.max(np.abs(at_half(out.x)))
    assert residual <= RESIDUAL, f"reference shooting: residual {residual:.1e}"
    return out.x[0], 2 * out.x[1]


def _load(path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    out = tmp_path_factory.mktemp("mass")
    for which in (1, 2):
        done = run("generate", DECIMAL, "--mode", which, "--order", "10", "--out", out)
        assert done.returncode == 0, done.stderr
    return {which: _load(out / f"mode{which}.py") for which in (1, 2)}


@pytest.mark.parametrize("which, grid", [(1, (0.3, 0.5, 0.7, 0.9)), (2, (0.5, 0.9, 1.3, 1.6))])
def test_decimal_full_mass_modules_meet_shooting_and_bound_their_error(modules, which, grid):
    """Each mode's module of a decimal system with a full mass and irrational ω₀: ω and x2(0)
    against shooting; error_estimate never below the true error, within 10× of it where the
    error is above rounding."""
    m = modules[which]
    lam = sorted(np.linalg.eigvals(np.linalg.solve(MASS, STIFFNESS)).real)
    assert abs(m.OMEGA0 / np.sqrt(lam[which - 1]) - 1) <= 1e-14
    checked = 0
    for A in grid:
        others, period = _shoot(A, m.x2(0.0, A), np.pi / m.omega(A))
        true = abs(m.period(A) / period - 1)
        assert abs(m.x2(0.0, A) - others) / A <= 10 * max(true, 1e-12)
        assert m.error_estimate(A) >= true or true < 1e-12, (A, m.error_estimate(A), true)
        if true > 1e-11:
            assert m.error_estimate(A) <= 10 * true, (A, m.error_estimate(A), true)
            checked += 1
    assert checked >= 2
    assert abs(m.omega(0.2) - 2 * np.pi / _shoot(0.2, m.x2(0.0, 0.2), np.pi / m.omega(0.2))[1]
               ) <= 1e-8


def test_nnm_of_a_full_mass_prints_decimals_and_its_json_keeps_the_mass(tmp_path):
    out = run("nnm", DECIMAL, "--order", "6", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    text = run("nnm", DECIMAL, "--order", "6")
    assert max(map(len, text.stdout.splitlines())) <= 200
    assert "0.866769338192" in text.stdout  # ω₀ of mode 1, as a decimal
    assert data["omega0_decimal"] == "0.866769338192"
    assert data["mass"] == [["6/5", "3/10"], ["3/10", "4/5"]]


@pytest.mark.parametrize("text, says", [
    ("x1'' + 2*x2'' + x1 = 0; 2*x1'' + x2'' + x2 = 0", "is not positive definite"),
    ("x1'' + 2*x2'' + x1 = 0; x1'' + x2'' + x2 = 0", "is not symmetric"),
    ("x1'' + x1 = 0; x1'' + x1 = 0", "one equation per coordinate"),
    ("-x1'' + x1 = 0; x2'' + x2 = 0", "mode 1 has ω0² = -1"),  # x1'' - x1 = 0, negated
    ("x1'' + x1 = 0;", "equation 2 is empty"),
    ("x1''*x2 + x1 = 0; x2'' + x2 = 0", "accelerations must enter linearly"),
])
def test_a_mass_that_is_not_one_is_refused_in_one_line(text, says):
    out = run("nnm", text)
    assert out.returncode == 2 and out.stdout == ""
    assert len(out.stderr.strip().splitlines()) == 1 and says in out.stderr, out.stderr


def test_an_equation_written_negated_is_the_same_system():
    """``-x1'' - 2*x1 + x2 - x1**3/2 = 0`` is Kerschen's first equation times −1: the same
    modes and series, exactly (it was refused as a negative mass)."""
    kerschen = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
    negated = "-x1'' - 2*x1 + x2 - x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
    for which in (1, 2):
        a, b = (normal_mode(parse_system(t), which, 6) for t in (kerschen, negated))
        assert a.omega() == b.omega() and a.period() == b.period()


# --- the system as written in floating point, sparse: from a text and from a model folder ---

def _chain(n: int) -> tuple:
    """A fixed–fixed chain of n unit masses and unit springs: K tridiagonal (2, −1), whose
    frequencies are 2 sin(kπ / (2(n + 1))) (the closed form, another route than an
    eigensolver)."""
    import scipy.sparse as sparse

    K = sparse.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    exact = 2 * np.sin(np.arange(1, n + 1) * np.pi / (2 * (n + 1)))
    return sparse.identity(n), K, exact


def test_text_system_as_written_in_floating_point():
    w = parse_system(DECIMAL).matrices
    assert np.allclose(w.mass.toarray(), MASS, rtol=0, atol=1e-15)
    assert np.allclose(w.stiffness.toarray(), STIFFNESS, rtol=0, atol=1e-15)
    assert w.damping is None and w.drive is None and w.force.degree == 3
    x = np.array([0.37, -1.21])
    assert np.allclose(w.force(x), _force(x), rtol=1e-15)
    # ∂f/∂x by hand: diag(1.2 x1², 0.6 x2²)
    assert np.allclose(w.force.jacobian(x).toarray(), np.diag([1.2 * x[0] ** 2,
                                                               0.6 * x[1] ** 2]), rtol=1e-15)
    lam = sp.Matrix(STIFFNESS.tolist()).applyfunc(sp.nsimplify)
    M = sp.Matrix(MASS.tolist()).applyfunc(sp.nsimplify)
    mu = sp.Symbol("mu")
    truth = sorted(float(sp.sqrt(r)) for r in sp.Poly((lam - mu * M).det(), mu).nroots(n=30))
    assert np.allclose(w.frequencies(2), truth, rtol=1e-14)


def test_driven_damped_text_system_keeps_c_and_f_as_written():
    s = parse_system("2*x1'' + 0.1*x1' + 3*x1 - x2 + x1**2*x2' = 0.5*cos(w*t); "
                     "x2'' + 0.2*x2' + 2*x2 - x1 = 0", driven=True)
    w = s.matrices
    assert np.allclose(w.damping.toarray(), np.diag([0.1, 0.2]), rtol=0, atol=1e-15)
    assert np.allclose(w.drive, [0.5, 0.0], rtol=0, atol=1e-15)
    x, v = np.array([0.3, -0.7]), np.array([1.1, 0.4])
    assert np.allclose(w.force(x, v), [x[0] ** 2 * v[1], 0.0], rtol=1e-15)
    assert not s.conservative


def test_model_folder_reads_into_the_same_record(tmp_path):
    from lindstedt.derive.nnm import normal_mode
    from lindstedt.derive.system import read_model
    from lindstedt.errors import InputError
    from scipy.io import mmwrite
    from scipy.sparse import coo_array

    mmwrite(tmp_path / "M.mtx", coo_array(MASS))
    mmwrite(tmp_path / "K.mtx", coo_array(STIFFNESS))
    # 0.4 x1³ written as two terms that add up, 0.2 x2³ as one
    (tmp_path / "nonlinear.txt").write_text("# i j k l c\n0 0 0 0 0.25\n0 0 0 0 0.15\n"
                                            "1 1 1 1 0.2\n")
    s = read_model(tmp_path)
    assert not s.exact and s.size == 2 and s.conservative
    x = np.array([-0.8, 0.45])
    assert np.allclose(s.matrices.force(x), _force(x), rtol=1e-15)
    assert np.allclose(s.matrices.frequencies(2), parse_system(DECIMAL).matrices.frequencies(2),
                       rtol=1e-14)
    with pytest.raises(InputError, match="no exact linear modes"):
        normal_mode(s, 1, 4)


def test_large_chain_model_frequencies_by_shift_invert(tmp_path):
    from lindstedt.derive.system import read_model
    from scipy.io import mmwrite

    n = 20000
    M, K, exact = _chain(n)
    mmwrite(tmp_path / "M.mtx", M)
    mmwrite(tmp_path / "K.mtx", K)
    (tmp_path / "nonlinear.txt").write_text(f"{n - 1} {n - 1} {n - 1} {n - 1} 2.5\n"
                                            "3 2 4 -1\n")
    (tmp_path / "drive.txt").write_text("0 1.5\n0 0.5\n")
    s = read_model(tmp_path)
    w = s.matrices
    assert w.mass.nnz == n and w.stiffness.nnz == 3 * n - 2  # nothing dense
    assert np.allclose(w.frequencies(4), exact[:4], rtol=1e-9)
    assert w.drive[0] == 2.0 and not s.conservative
    x = np.linspace(-1, 1, n)
    f = w.force(x)
    assert f[n - 1] == 2.5 * x[n - 1] ** 3 and f[3] == -x[2] * x[4]
    assert np.count_nonzero(f) == 2
    J = w.force.jacobian(x)
    assert J.nnz <= 3 and J[3, 2] == -x[4] and J[3, 4] == -x[2]


@pytest.mark.parametrize("files, message", [
    ({"M.mtx": None}, "K.mtx is missing"),
    ({"M.mtx": None, "K.mtx": [[2.0, -1.0], [-1.5, 2.0]]}, "K.mtx is not symmetric"),
    ({"M.mtx": [[1.0, 0.0], [0.0, 0.0]], "K.mtx": None}, r"M\[1,1\] = 0"),
    ({"M.mtx": [[1.0, 2.0], [2.0, 1.0]], "K.mtx": None},
     r"M.mtx is not positive definite \(its smallest eigenvalue is -1"),
    ({"M.mtx": None, "K.mtx": [[2.0]]}, "K.mtx is 1×1 and M.mtx 2×2"),
    ({"M.mtx": None, "K.mtx": None, "nonlinear.txt": "0 0 2 1.0\n"},
     "nonlinear.txt line 1: index 2 outside 0..1"),
    ({"M.mtx": None, "K.mtx": None, "nonlinear.txt": "0 0 1.0\n"},
     "nonlinear.txt line 1: 3 fields; 4 or 5 expected"),
    ({"M.mtx": None, "K.mtx": None, "drive.txt": "1 inf\n"},
     "drive.txt line 1: the coefficient inf is not finite"),
    ({"M.mtx": "not a matrix\n", "K.mtx": None}, "M.mtx: not a Matrix Market matrix"),
])
def test_model_folder_refusals_name_the_file(tmp_path, files, message):
    from lindstedt.derive.system import read_model
    from lindstedt.errors import InputError
    from scipy.io import mmwrite
    from scipy.sparse import coo_array

    defaults = {"M.mtx": [[1.0, 0.0], [0.0, 1.0]], "K.mtx": [[2.0, -1.0], [-1.0, 2.0]]}
    for name, content in files.items():
        if isinstance(content, str):
            (tmp_path / name).write_text(content)
        else:
            mmwrite(tmp_path / name, coo_array(np.array(content or defaults[name])))
    with pytest.raises(InputError, match=message):
        read_model(tmp_path)
