"""A clamped–clamped von Kármán beam by finite elements, written as a model folder.

    .venv/bin/python examples/beam_model.py OUT_FOLDER [--elements 40] [--zeta 0.01]
        [--force 0.1] [--length 1] [--width 0.02] [--thickness 0.002]
        [--young 210e9] [--density 7850]
    lindstedt ssm --model OUT_FOLDER --mode 1 --order 7 --output IDX

The model.  An Euler–Bernoulli beam of length ``L``, rectangular section ``b × t``
(``A = b t``, ``I = b t³/12``), Young's modulus ``E`` and density ``ρ``, both ends clamped
(``u = w = w' = 0``: the ends cannot move axially either, so bending stretches the beam and
it stiffens — the hardening of a clamped plate or MEMS beam).  ``u(x)`` is the axial and
``w(x)`` the transverse displacement; the strain is von Kármán's ``ε = u' + ½ w'²`` and the
strain energy ``V = ½ ∫ (EA ε² + EI w''²) dx``.  Its quadratic part is ``½ xᵀ K x``; the rest,

    V₃ = ½ EA ∫ u' w'² dx,        V₄ = ⅛ EA ∫ w'⁴ dx,

gives the nonlinear force ``f(x) = ∂(V₃ + V₄)/∂x``: quadratic terms ``u_a w_b`` and
``w_a w_b`` (the axial–transverse coupling) and cubic terms ``w_a w_b w_c`` (the stretching).
The kinetic energy is ``½ ∫ ρA (u̇² + ẇ²) dx`` (consistent mass; no rotary inertia); the
damping is Rayleigh's ``C = α M + β K`` with ``α, β`` giving the damping ratio ``--zeta`` to
the model's first two bending modes; the drive is a point force ``--force · cos ωt`` at
mid-span, transverse.  The equations are ``M x'' + C x' + K x + f(x) = F cos ωt``.

The elements.  ``--elements N`` (even) elements of length ``h = L/N``; in each, ``u`` is
linear (Lagrange) and ``w`` cubic (Hermite: ``w`` and ``w'`` at both nodes), six DOFs
``(u₁, w₁, w'₁, u₂, w₂, w'₂)``.  Every element integral is a polynomial in ``ξ = x/h``,
integrated exactly once, in rationals, on the reference element (:func:`reference`), then
scaled by the element's powers of ``h`` and by ``EA``, ``EI``, ``ρA``: mass and stiffness
matrices and the nonlinear force's coefficients are exact up to one rounding each.  Each
element's terms couple its own six DOFs only, so the nonzeros grow with ``N``.

The DOF numbering.  Nodes ``k = 0 … N`` at ``x = k h``; the clamped end nodes ``0`` and ``N``
are removed, and interior node ``k = 1 … N − 1`` holds

    3(k − 1)      u(kh)    axial displacement       [m]
    3(k − 1) + 1  w(kh)    transverse displacement  [m]
    3(k − 1) + 2  w'(kh)   slope                    [rad]

so ``n = 3(N − 1)`` and the matrices are banded.  The mid-span transverse displacement is DOF
``3(N/2 − 1) + 1``; the command prints it (``--output IDX`` of ``lindstedt ssm``).

Units.  SI throughout (m, kg, s, N, Pa; frequencies in rad/s).  The defaults are a steel
strip 1 m × 20 mm × 2 mm (``E = 210 GPa``, ``ρ = 7850 kg/m³``): first bending frequency
66.8 rad/s (10.6 Hz); the first axial one is about 240 times higher.  A nondimensional beam
is ``--young 1 --density 1 …`` with the section's sizes of one's choice.

The folder (what ``lindstedt.derive.system.read_model`` reads): ``M.mtx``, ``K.mtx``,
``C.mtx`` (Matrix Market, symmetric storage, every number to its shortest round-trip
digits), ``nonlinear.txt`` (a term a line, 0-based: ``i j k c`` adds ``c·x_j·x_k`` to
``f_i``, ``i j k l c`` adds ``c·x_j·x_k·x_l``; each distinct monomial once per equation, its
indices ascending; a header of ``#`` comments names the beam and the DOFs) and ``drive.txt``
(``i F_i``).  The same arguments write the same files, byte for byte.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from collections import defaultdict
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from pathlib import Path

import numpy as np
import scipy.sparse as sparse
from scipy.io import mmwrite

U_DOFS = (0, 3)  # the element's axial DOFs u₁, u₂
W_DOFS = (1, 2, 4, 5)  # its bending DOFs w₁, w'₁, w₂, w'₂
DENSE = 200  # up to this size the modes come from a dense eigenproblem, else shift-invert Lanczos


@dataclass(frozen=True)
class Beam:
    """A clamped–clamped beam, SI units, meshed by ``elements`` (even) equal elements."""

    length: float = 1.0  # L [m]
    width: float = 0.02  # b [m]
    thickness: float = 0.002  # t [m]
    young: float = 210e9  # E [Pa]
    density: float = 7850.0  # ρ [kg/m³]
    elements: int = 40  # N

    @property
    def h(self) -> float:
        return self.length / self.elements

    @property
    def EA(self) -> float:
        return self.young * self.width * self.thickness

    @property
    def EI(self) -> float:
        return self.young * self.width * self.thickness**3 / 12

    @property
    def rhoA(self) -> float:
        return self.density * self.width * self.thickness

    @property
    def size(self) -> int:
        """The number of DOFs, ``3(N − 1)``."""
        return 3 * (self.elements - 1)

    @property
    def midspan(self) -> int:
        """The index of the mid-span transverse displacement ``w(L/2)``."""
        return 3 * (self.elements // 2 - 1) + 1


# --- the reference element: exact integrals of polynomials in ξ = x/h ∈ [0, 1] -------------

# A shape function is (coefficients of a polynomial p(ξ), ascending; the power s of h), its
# value h^s p(ξ).  d/dx = (1/h) d/dξ lowers s by one.
SHAPES = {
    0: ((1, -1), 0),  # u₁: 1 − ξ
    1: ((1, 0, -3, 2), 0),  # w₁: 1 − 3ξ² + 2ξ³
    2: ((0, 1, -2, 1), 1),  # w'₁: h (ξ − 2ξ² + ξ³)
    3: ((0, 1), 0),  # u₂: ξ
    4: ((0, 0, 3, -2), 0),  # w₂: 3ξ² − 2ξ³
    5: ((0, 0, -1, 1), 1),  # w'₂: h (−ξ² + ξ³)
}


def _derivative(shape: tuple[tuple[int, ...], int], order: int) -> tuple[tuple[int, ...], int]:
    """The ``order``-th x-derivative of a shape function."""
    p, s = shape
    for _ in range(order):
        p = tuple(k * c for k, c in enumerate(p))[1:] or (0,)
        s -= 1
    return p, s


def _integral(shapes: list[tuple[tuple[int, ...], int]]) -> tuple[Fraction, int]:
    """``∫₀ʰ Π shapes dx`` as ``(r, s)``: the exact rational ``r`` times ``h^s``."""
    product = (1,)
    for p, _ in shapes:
        out = [0] * (len(product) + len(p) - 1)
        for i, a in enumerate(product):
            for j, b in enumerate(p):
                out[i + j] += a * b
        product = tuple(out)
    r = sum((Fraction(c, k + 1) for k, c in enumerate(product)), Fraction(0))
    return r, 1 + sum(s for _, s in shapes)


@cache
def reference() -> dict[str, dict]:
    """The element's integrals, exact: ``mass``/``stiffness`` ``{(a, b): (r, s)}`` (of
    ``ρA``, and of ``EA`` for ``a, b`` axial, ``EI`` for bending), and ``force`` ``{(i,
    factors): (r, s)}`` (of ``EA``): the gradient of ``V₃ + V₄``, each distinct monomial
    ``Π x_factors`` once per equation ``i``, ``factors`` ascending."""
    d1 = {a: _derivative(SHAPES[a], 1) for a in SHAPES}
    d2 = {a: _derivative(SHAPES[a], 2) for a in W_DOFS}
    mass, stiffness = {}, {}
    for dofs in (U_DOFS, W_DOFS):
        for a, b in itertools.product(dofs, repeat=2):
            mass[a, b] = _integral([SHAPES[a], SHAPES[b]])
            stiffness[a, b] = _integral([d1[a], d1[b]] if dofs == U_DOFS else [d2[a], d2[b]])
    energy: dict[tuple[int, ...], list] = defaultdict(lambda: [Fraction(0), None])
    # V₃ = ½ EA ∫ u' w'²,  V₄ = ⅛ EA ∫ w'⁴: summed over ordered index tuples, gathered by
    # monomial (the sorted tuple)
    products = [(Fraction(1, 2), U_DOFS, W_DOFS, W_DOFS),
                (Fraction(1, 8), W_DOFS, W_DOFS, W_DOFS, W_DOFS)]
    for weight, *sets in products:
        for dofs in itertools.product(*sets):
            r, s = _integral([d1[a] for a in dofs])
            term = energy[tuple(sorted(dofs))]
            term[0] += weight * r
            assert term[1] in (None, s)  # a monomial has one power of h
            term[1] = s
    force: dict[tuple[int, tuple[int, ...]], tuple[Fraction, int]] = {}
    for monomial, (r, s) in energy.items():
        if r == 0:
            continue
        for i in sorted(set(monomial)):  # ∂/∂x_i of r x^monomial
            rest = list(monomial)
            rest.remove(i)
            key = (i, tuple(rest))
            previous = force.get(key, (Fraction(0), s))[0]
            force[key] = (previous + monomial.count(i) * r, s)
    return {"mass": mass, "stiffness": stiffness,
            "force": {k: v for k, v in sorted(force.items()) if v[0] != 0}}


# --- one element, in floats ----------------------------------------------------------------


def element_matrices(beam: Beam) -> tuple[np.ndarray, np.ndarray]:
    """The element's 6×6 consistent mass and stiffness matrices."""
    ref = reference()
    M, K = np.zeros((6, 6)), np.zeros((6, 6))
    for (a, b), (r, s) in ref["mass"].items():
        M[a, b] = beam.rhoA * float(r) * beam.h**s
    for (a, b), (r, s) in ref["stiffness"].items():
        K[a, b] = (beam.EA if a in U_DOFS else beam.EI) * float(r) * beam.h**s
    return M, K


def element_terms(beam: Beam) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The element's nonlinear force as a table: equation (T,), factors (T, 3) padded with −1
    (a quadratic term), coefficient (T,), in local DOFs."""
    force = reference()["force"]
    equation = np.array([i for i, _ in force], dtype=np.int64)
    factors = np.array([[*f, -1][:3] for _, f in force], dtype=np.int64)
    coefficient = np.array([beam.EA * float(r) * beam.h**s for r, s in force.values()])
    return equation, factors, coefficient


# --- assembly ----------------------------------------------------------------------------------


def dof_table(beam: Beam) -> np.ndarray:
    """``(N, 6)``: each element's six DOFs ``(u₁, w₁, w'₁, u₂, w₂, w'₂)`` as global indices,
    −1 where clamped (the end nodes)."""
    node = np.arange(beam.elements + 1)
    index = 3 * (node[:, None] - 1) + np.arange(3)
    index[[0, -1]] = -1
    return np.hstack([index[:-1], index[1:]])


def assemble_matrix(local: np.ndarray, dofs: np.ndarray, n: int) -> sparse.csr_array:
    """The global matrix of one local matrix repeated on every element (clamped DOFs
    dropped), with the zeros that cancel in the sum removed."""
    rows = np.repeat(dofs, 6, axis=1)
    cols = np.tile(dofs, (1, 6))
    values = np.broadcast_to(local.ravel(), rows.shape)
    keep = (rows >= 0) & (cols >= 0) & (values != 0)
    A = sparse.csr_array((values[keep], (rows[keep], cols[keep])), shape=(n, n))
    A.sum_duplicates()
    A.eliminate_zeros()
    return A


def assemble_terms(beam: Beam, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The global nonlinear force: every element's terms, those of a clamped DOF dropped,
    repeated ``(i, factors)`` merged and exact cancellations removed; sorted by equation,
    degree, factors.  Returns equation (T,), factors (T, 3) padded with −1, coefficient."""
    equation, factors, coefficient = element_terms(beam)
    pad = factors < 0
    eq = dofs[:, equation].ravel()
    fac = dofs[:, np.where(pad, 0, factors)]  # (N, T, 3)
    clamped = ((fac < 0) & ~pad).any(axis=2).ravel() | (eq < 0)
    fac = np.where(pad, -1, fac).reshape(-1, 3)
    c = np.broadcast_to(coefficient, (beam.elements, len(coefficient))).ravel()
    eq, fac, c = eq[~clamped], fac[~clamped], c[~clamped]
    degree = 3 - (fac[:, 2] < 0)
    order = np.lexsort((fac[:, 2], fac[:, 1], fac[:, 0], degree, eq))
    key = np.column_stack([eq, fac])[order]
    first = np.ones(len(key), dtype=bool)
    first[1:] = (key[1:] != key[:-1]).any(axis=1)
    starts = np.flatnonzero(first)
    merged = np.add.reduceat(c[order], starts) if len(starts) else np.zeros(0)
    keep = merged != 0
    return key[starts, 0][keep], key[starts, 1:][keep], merged[keep]


@dataclass(frozen=True)
class Model:
    """``M x'' + C x' + K x + f(x) = F cos ωt`` assembled: sparse ``M``, ``K``, ``C``, the
    force's table, the drive, Rayleigh's ``α, β`` and the bending and axial frequencies."""

    beam: Beam
    mass: sparse.csr_array
    stiffness: sparse.csr_array
    damping: sparse.csr_array
    terms: tuple[np.ndarray, np.ndarray, np.ndarray]
    drive: np.ndarray
    rayleigh: tuple[float, float]
    bending: np.ndarray  # the lowest bending frequencies [rad/s]
    axial: np.ndarray  # the lowest axial frequencies [rad/s]


def lowest_frequencies(K: sparse.csr_array, M: sparse.csr_array, count: int) -> np.ndarray:
    """The ``count`` lowest ``ω`` of ``K φ = ω² M φ`` (fewer where the size is smaller):
    dense up to :data:`DENSE` DOFs, else shift-invert Lanczos about 0 from a fixed start (the
    same digits every run), each solve with ``K`` refined once (:func:`refined_solver`)."""
    n = K.shape[0]
    count = min(count, n)
    if n <= DENSE:
        from scipy.linalg import eigh

        lam = eigh(K.toarray(), M.toarray(), eigvals_only=True, subset_by_index=[0, count - 1])
    else:
        from scipy.sparse.linalg import LinearOperator, eigsh

        solve = LinearOperator(K.shape, matvec=refined_solver(K), dtype=float)
        lam = eigsh(K.tocsc(), count, M.tocsc(), sigma=0, which="LM", OPinv=solve,
                    v0=np.ones(n), return_eigenvectors=False)
    return np.sqrt(np.sort(lam))


def refined_solver(K: sparse.csr_array):
    """``b ↦ K⁻¹ b`` by a sparse LU and one step of iterative refinement, the residual
    ``b − K y`` in extended precision (``np.longdouble``; plain double where the platform
    has no wider type).  A bending stiffness's condition grows as ``N⁴``: a plain solve
    leaves the lowest frequency of 10 000 elements wrong by 1e-4, the refined one by 4e-8
    (its matrices hold it to 1e-9: the Rayleigh quotient of the analytic mode, in exact
    arithmetic)."""
    from scipy.sparse.linalg import splu

    lu = splu(K.tocsc())
    wide = K.astype(np.longdouble)

    def solve(b: np.ndarray) -> np.ndarray:
        b = np.ravel(b)
        y = lu.solve(b)
        residual = b.astype(np.longdouble) - wide @ y.astype(np.longdouble)
        return y + lu.solve(residual.astype(float))

    return solve


def rayleigh(zeta: float, w1: float, w2: float) -> tuple[float, float]:
    """``α, β`` of ``C = αM + βK`` giving the damping ratio ``zeta`` at ``w1`` and ``w2``
    (``ζ(ω) = α/(2ω) + βω/2``)."""
    w1, w2 = float(w1), float(w2)
    return 2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2)


def assemble(beam: Beam, zeta: float = 0.01, force: float = 0.1, count: int = 5) -> Model:
    """The beam's model: matrices, nonlinear terms, drive, and ``count`` lowest bending and
    axial frequencies (the first two bending ones set the damping)."""
    if beam.elements < 2 or beam.elements % 2:
        raise ValueError(f"--elements {beam.elements}: an even number ≥ 2 (a node at mid-span)")
    n = beam.size
    dofs = dof_table(beam)
    Me, Ke = element_matrices(beam)
    M, K = assemble_matrix(Me, dofs, n), assemble_matrix(Ke, dofs, n)
    axial_dofs = np.arange(0, n, 3)
    bending_dofs = np.setdiff1d(np.arange(n), axial_dofs)

    def block(A: sparse.csr_array, index: np.ndarray) -> sparse.csr_array:
        return A[index][:, index]

    bending = lowest_frequencies(block(K, bending_dofs), block(M, bending_dofs), count)
    axial = lowest_frequencies(block(K, axial_dofs), block(M, axial_dofs), count)
    if len(bending) < 2:
        raise ValueError(f"--elements {beam.elements}: Rayleigh damping needs two bending "
                         "modes (at least 4 elements)")
    alpha, beta = rayleigh(zeta, bending[0], bending[1])
    C = (alpha * M + beta * K).tocsr()
    C.eliminate_zeros()
    F = np.zeros(n)
    F[beam.midspan] = force
    return Model(beam, M, K, C, assemble_terms(beam, dofs), F, (alpha, beta), bending, axial)


# --- the folder ----------------------------------------------------------------------------


def describe(model: Model) -> list[str]:
    """The header of the folder's text files (ASCII): the beam, its parameters, the DOFs."""
    b = model.beam
    alpha, beta = model.rayleigh
    return [
        f"von Karman beam, clamped-clamped, {b.elements} Euler-Bernoulli elements "
        "(examples/beam_model.py), SI units",
        f"L = {b.length!r} m, section {b.width!r} x {b.thickness!r} m, E = {b.young!r} Pa, "
        f"rho = {b.density!r} kg/m^3; EA = {b.EA!r}, EI = {b.EI!r}, rhoA = {b.rhoA!r}",
        "M x'' + C x' + K x + f(x) = F cos(w t), C = alpha M + beta K, "
        f"alpha = {alpha!r}, beta = {beta!r}",
        f"{b.size} DOFs: interior node k = 1..{b.elements - 1} at x = k*{b.h!r} m holds "
        "3(k-1): u (axial, m), 3(k-1)+1: w (transverse, m), 3(k-1)+2: w' (slope, rad)",
        f"mid-span transverse displacement w(L/2): DOF {b.midspan}",
    ]


def nonlinear_text(model: Model) -> str:
    """``nonlinear.txt``: the header, then ``i j k c`` and ``i j k l c`` lines, ``c`` by
    ``repr`` (round-trips)."""
    equation, factors, coefficient = model.terms
    header = [*describe(model),
              "f(x) = grad of (EA/2) int u' w'^2 dx + (EA/8) int w'^4 dx over the elements",
              "i j k c: c*x_j*x_k in f_i; i j k l c: c*x_j*x_k*x_l in f_i (0-based, "
              f"each monomial once per equation); {len(coefficient)} terms"]
    lines = ["# " + line for line in header]
    for i, f, c in zip(equation.tolist(), factors.tolist(), coefficient.tolist(), strict=True):
        lines.append(" ".join(str(k) for k in (i, *f) if k >= 0) + f" {c!r}")
    return "\n".join(lines) + "\n"


def write_folder(model: Model, folder: Path) -> None:
    """``M.mtx``, ``K.mtx``, ``C.mtx``, ``nonlinear.txt``, ``drive.txt`` in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    comment = "\n".join(describe(model))
    for name, A in (("M", model.mass), ("K", model.stiffness), ("C", model.damping)):
        mmwrite(folder / f"{name}.mtx", A, comment=f"{name}: {comment}", symmetry="symmetric")
    (folder / "nonlinear.txt").write_text(nonlinear_text(model), encoding="ascii")
    drive = [f"# {line}" for line in describe(model)]
    drive += ["# i F_i: a point force at mid-span, transverse [N]"]
    drive += [f"{i} {F!r}" for i, F in enumerate(model.drive.tolist()) if F != 0]
    (folder / "drive.txt").write_text("\n".join(drive) + "\n", encoding="ascii")


def clamped_roots(count: int) -> list[float]:
    """The first ``count`` roots ``βL`` of ``cos βL cosh βL = 1`` (clamped–clamped)."""
    from scipy.optimize import brentq

    return [brentq(lambda x: math.cos(x) - 1 / math.cosh(x), (k + 0.5) * math.pi - 0.5,
                   (k + 0.5) * math.pi + 0.5, xtol=1e-14) for k in range(1, count + 1)]


def report(model: Model, folder: Path, count: int = 5) -> str:
    """What the command prints: size, nonzeros, the lowest frequencies, the output DOF."""
    b = model.beam
    scale = math.sqrt(b.EI / b.rhoA) / b.length**2
    analytic = [r * r * scale for r in clamped_roots(len(model.bending))]
    modes = sorted([(w, "bending", k) for k, w in enumerate(model.bending)]
                   + [(w, "axial", k) for k, w in enumerate(model.axial)])[:count]
    nnz = {name: A.nnz for name, A in (("M", model.mass), ("K", model.stiffness),
                                       ("C", model.damping))}
    lines = [f"{folder}: n = {b.size} DOFs, nnz M {nnz['M']}, K {nnz['K']}, C {nnz['C']}, "
             f"{len(model.terms[2])} nonlinear terms",
             "lowest linear frequencies (rad/s; Euler-Bernoulli's clamped-clamped beside "
             "the bending ones):"]
    for j, (w, kind, k) in enumerate(modes, 1):
        exact = (f"   Euler-Bernoulli {analytic[k]:.10g} (rel. {w / analytic[k] - 1:+.1e})"
                 if kind == "bending" else "")
        lines.append(f"  {j}: {w:.10g}  ({w / (2 * math.pi):.6g} Hz, {kind} {k + 1}){exact}")
    alpha, beta = model.rayleigh
    lines += [f"Rayleigh damping alpha = {alpha:.6g}, beta = {beta:.6g} "
              "(zeta on bending modes 1 and 2)",
              f"mid-span transverse displacement: DOF {b.midspan}",
              f"  lindstedt ssm --model {folder} --mode 1 --order 7 --output {b.midspan}"]
    return "\n".join(lines)


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        description="Write a clamped-clamped von Karman beam (finite elements) as a model "
        "folder: M.mtx, K.mtx, C.mtx, nonlinear.txt, drive.txt.")
    parser.add_argument("folder", type=Path, help="the folder to write (made if absent)")
    parser.add_argument("--elements", type=int, default=Beam.elements,
                        help="number of elements, even (default %(default)s)")
    parser.add_argument("--zeta", type=float, default=0.01,
                        help="damping ratio of bending modes 1 and 2 (default %(default)s)")
    parser.add_argument("--force", type=float, default=0.1,
                        help="amplitude of the mid-span point force, N (default %(default)s)")
    parser.add_argument("--length", type=float, default=Beam.length, help="L, m")
    parser.add_argument("--width", type=float, default=Beam.width, help="b, m")
    parser.add_argument("--thickness", type=float, default=Beam.thickness, help="t, m")
    parser.add_argument("--young", type=float, default=Beam.young, help="E, Pa")
    parser.add_argument("--density", type=float, default=Beam.density, help="rho, kg/m^3")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    beam = Beam(args.length, args.width, args.thickness, args.young, args.density,
                args.elements)
    try:
        model = assemble(beam, args.zeta, args.force)
    except ValueError as exc:
        print(f"beam_model: {exc}", file=sys.stderr)
        return 2
    write_folder(model, args.folder)
    print(report(model, args.folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
