"""A user's driven oscillator ``q̈ + g(q, q̇) = Σ f_i cos ν_i t``, ``g`` a polynomial: its
equation lowered to data (:class:`DrivenEquation`, :class:`DrivenForm`), the Galerkin
balance of any polynomial force by alternating frequency and time (:class:`PolynomialBalance`)
and a bound on its orbits' amplitude."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..algebra.series import laurent_from_fourier
from ..display import harmonics_table
from ..errors import InputError
from ..limits import MAGNITUDES, MAX_HARMONICS, check_int
from ..numerics.integrate import PolynomialField
from ..numerics.newton import newton

# --- a user's driven oscillator: q'' + g(q, q') = f cos(w t), g a polynomial -----------------

DRIVEN = "driven"


def check_harmonics(harmonics: object) -> None:
    """:class:`InputError` unless ``harmonics`` is an integer in 1..MAX_HARMONICS."""
    check_int(harmonics, 1, MAX_HARMONICS,
              f"harmonics {harmonics!r}: must be an integer in 1..{MAX_HARMONICS}")


@dataclass(frozen=True)
class DrivenEquation:
    """A user's equation lowered to data: ``q̈ + Σ c q^a q̇^b = f cos ωt`` at one ω.

    ``terms`` maps ``(a, b)`` to the float ``c`` (the linear part included); ``force`` is the
    drive amplitude ``f``, ``omega`` the drive frequency (the value of ``frequency``, the
    symbol in the cosine's argument), ``values`` the parameter values as given (text)."""

    name: str
    text: str
    terms: dict[tuple[int, int], float]
    force: float
    omega: float
    frequency: str
    values: tuple[tuple[str, str], ...]

    @property
    def odd(self) -> bool:
        """``g(−q, −q̇) = −g(q, q̇)``: the response holds odd harmonics only."""
        return all((a + b) % 2 == 1 for a, b in self.terms)

    @property
    def dissipative(self) -> bool:
        """A term odd in ``q̇``: stability asks every Floquet multiplier inside the unit circle."""
        return any(b % 2 == 1 for _, b in self.terms)

    @property
    def degree(self) -> int:
        """The highest total degree ``a + b`` of the force's terms."""
        return max(a + b for a, b in self.terms)

    @property
    def where(self) -> str:
        """The equation named in one line: ``name (text; k = v, …)``."""
        given = ", ".join(f"{k} = {v}" for k, v in self.values)
        return f"{self.name} ({self.text}{'; ' if given else ''}{given})"


def driven_equation(text: str, values: dict[str, str], omega: float,
                    name: str = "oscillator") -> DrivenEquation:
    """Lower ``text`` (see :mod:`lindstedt.derive.equation`) to a :class:`DrivenEquation`: a
    polynomial force and a single drive ``f cos(w t)``, every parameter but ``w`` given in
    ``values`` (exact text, ``eps`` included), ``w = omega``.  A one-line :class:`InputError`
    says why where it cannot: no drive or more than one, a drive that is not ``f cos(w t)``, a
    term in both t and q (parametric), a force that is not a polynomial in q and q', a missing
    value."""
    from ..derive.equation import parse_expression
    from ..derive.models import oscillator

    if isinstance(omega, bool) or not isinstance(omega, (int, float)) \
            or not math.isfinite(omega) or omega <= 0:
        raise InputError(f"--omega {omega!r}: the drive frequency must be finite and > 0")
    values = dict(values)
    small = values.pop("eps", None)
    osc = oscillator(text, values, name)
    q, v, t = osc.coordinate, osc.velocity, osc.equation.time
    subs: dict[sp.Symbol, sp.Expr] = {}
    if small is not None:
        if osc.equation.small is None:
            raise InputError(f"--param eps: not a parameter of {text!r}")
        number = parse_expression(small, "--param eps")
        if not number.is_Rational:
            raise InputError(f"--param eps={small}: not a rational number")
        subs[osc.equation.small] = number
    if osc.parametric != 0:
        raise osc.refuse(DRIVEN, f"{sp.sstr(osc.parametric)} depends on both t and {q} "
                         "(parametric excitation); give a drive in t alone")
    drive = osc.drive.xreplace(subs)
    if drive == 0:
        raise osc.refuse(DRIVEN, f"no drive: write it on the right, e.g. {q}'' + ... = "
                         "f*cos(w*t)")
    terms = sp.Add.make_args(sp.expand(drive))
    if len(terms) > 1:
        raise osc.refuse(DRIVEN, f"the drive {sp.sstr(drive)} has {len(terms)} terms; it takes "
                         "one, f*cos(w*t) (several tones: `lindstedt mixing`)")
    amplitude, wave = drive.as_independent(t, as_Add=False)
    if not isinstance(wave, sp.cos):
        raise osc.refuse(DRIVEN, f"the drive {sp.sstr(drive)} is not f*cos(w*t) (a sine or "
                         "another function of t: shift t or rewrite it as f*cos(w*t))")
    w, rest = wave.args[0].as_independent(t, as_Add=False)
    if rest != t or not isinstance(w, sp.Symbol):
        raise osc.refuse(DRIVEN, f"the drive's argument {sp.sstr(wave.args[0])} is not w*t "
                         "with the frequency a name w (its value is --omega)")
    if str(w) in values:
        raise InputError(f"--param {w}: {w} is the drive frequency; give it with --omega")
    subs[w] = sp.Rational(str(float(omega)))
    force_expr = sp.expand(osc.force.xreplace(subs))
    amplitude = amplitude.xreplace(subs)
    missing = sorted(str(s) for s in (force_expr.free_symbols | amplitude.free_symbols)
                     - {q, v})
    if missing:
        raise osc.refuse(DRIVEN, "give " + ", ".join(missing) + " a value (--param "
                         + " --param ".join(f"{m}=..." for m in missing) + ")")
    if not force_expr.is_polynomial(q, v):
        raise osc.refuse(DRIVEN, f"the force {sp.sstr(osc.force)} is not a polynomial in {q} "
                         f"and {v} (expand it: driven evaluates polynomial forces)")
    poly = sp.Poly(force_expr, q, v)
    table: dict[tuple[int, int], float] = {}
    for (a, b), c in zip(poly.monoms(), poly.coeffs(), strict=True):
        value = float(c)
        if not math.isfinite(value) or (value != 0 and not MAGNITUDES[0] <= abs(value)
                                        <= MAGNITUDES[1]):
            raise osc.refuse(DRIVEN, f"the coefficient {c} of {sp.sstr(q**a * v**b)} is "
                             f"outside {MAGNITUDES[0]:g}..{MAGNITUDES[1]:g}")
        if value != 0:
            table[(a, b)] = value
    if table.get((0, 0)):
        raise osc.refuse(DRIVEN, f"the constant force {table[(0, 0)]:g} moves the equilibrium "
                         f"off {q} = 0; shift {q} to it")
    if not any(a + b == 1 for a, b in table) and (1, 0) not in table:
        raise osc.refuse(DRIVEN, f"no linear term in {q}: q = 0 is no oscillator's equilibrium")
    f = float(amplitude)
    if f == 0 or not math.isfinite(f) or not MAGNITUDES[0] <= abs(f) <= MAGNITUDES[1]:
        raise osc.refuse(DRIVEN, f"the drive amplitude {amplitude} must be nonzero, within "
                         f"{MAGNITUDES[0]:g}..{MAGNITUDES[1]:g}")
    given = [(k, str(val)) for k, val in sorted({**values, **({"eps": small} if small
                                                               else {})}.items())]
    return DrivenEquation(name, text, table, f, float(omega), str(w), tuple(given))


class PolynomialBalance:
    """The Galerkin residual of ``q̈ + g(q, q̇) = f cos ωt`` for a polynomial ``g`` (a
    :class:`DrivenEquation`'s terms), by alternating frequency and time: ``q`` and ``q̇`` sampled
    on ``S`` points of a period, ``g`` evaluated there, projected back on the harmonics.  ``S``
    exceeds ``(degree + 1)`` times the top harmonic, so no product aliases: the projection is the
    exact Galerkin residual (as :class:`BalanceSystem`'s convolutions are for εq³).

    A system ``ẍ_i + g_i(x, ẋ) = d_i f cos ωt`` is the same balance with ``terms`` one
    ``{(a₁ … a_n, b₁ … b_n): c}`` per equation (:class:`numerics.integrate.PolynomialField`)
    and ``shape = (d₁ … d_n)``: its unknowns are each coordinate's, one block after another.

    ``drive_harmonic = n`` puts the drive on ``cos nωt`` instead: the balance of a 1/n
    subharmonic, ω its own frequency.
    Unknowns ``x = (a_k …, b_k …)`` of ``q = Σ a_k cos kωt + b_k sin kωt`` over ``orders``:
    ``1, 3, …, 2N − 1`` for an odd force (:class:`BalanceSystem`'s layout), else
    ``0, 1, 2, …, 2N − 1`` (the constant ``a_0``, no ``b_0``).  The same interface as
    :class:`BalanceSystem` (``residual``, ``jacobian``, ``d_omega`` in ``(x, ω)``), with the drive
    amplitude ``force`` as a keyword for the continuation in it."""

    def __init__(self, terms: dict[tuple[int, int], float]
                 | tuple[dict[tuple[int, ...], float], ...], force: float, harmonics: int,
                 odd: bool, drive_harmonic: int = 1,
                 shape: tuple[float, ...] = (1.0,)) -> None:
        check_harmonics(harmonics)
        equations = (dict(terms),) if isinstance(terms, dict) else tuple(map(dict, terms))
        if len(shape) != len(equations):
            raise ValueError("PolynomialBalance: one drive entry per equation")
        self.field = PolynomialField.of(equations)
        self.terms = equations[0] if isinstance(terms, dict) else equations
        self.force, self.harmonics, self.odd = force, harmonics, odd
        self.coordinates = len(equations)
        self.drive_harmonic = drive_harmonic
        top = 2 * harmonics - 1
        if drive_harmonic > top or (odd and drive_harmonic % 2 == 0):
            raise InputError(f"harmonic {drive_harmonic} of the drive is not among the "
                             f"balance's orders (top {top}{', odd only' if odd else ''})")
        self.orders = np.arange(1, top + 1, 2) if odd else np.arange(0, top + 1)
        samples = 16
        while samples <= (self.field.degree + 1) * top:
            samples *= 2
        k = self.orders
        sines = k[k > 0]
        self.n_cos = len(k)
        self.basis, self.d_basis = self._bases(samples)  # (S, m): q = basis @ x, d/dθ
        weights = np.concatenate([np.where(k == 0, 1.0, 2.0), np.full(len(sines), 2.0)])
        self.project = (weights * self.basis).T / samples  # the harmonics of samples
        self.k2 = np.concatenate([k, sines]).astype(float) ** 2
        block = np.zeros(len(self.k2))
        # the cos(n ωt) component, n = drive_harmonic (n > 1: a 1/n subharmonic's balance)
        block[int(np.nonzero(k == drive_harmonic)[0][0])] = 1.0
        self.drive = np.concatenate([d * block for d in shape])
        self._last: tuple = (None, None)

    def _bases(self, samples: int) -> tuple[np.ndarray, np.ndarray]:
        """``cos kθ, sin kθ`` over the orders on ``samples`` points, and their θ-derivatives."""
        theta = 2 * np.pi * np.arange(samples) / samples
        k = self.orders
        sines = k[k > 0]
        return (np.hstack([np.cos(np.outer(theta, k)), np.sin(np.outer(theta, sines))]),
                np.hstack([-k * np.sin(np.outer(theta, k)),
                           sines * np.cos(np.outer(theta, sines))]))

    @property
    def size(self) -> int:
        """The number of unknowns (the cosine and sine amplitudes of every coordinate)."""
        return self.coordinates * len(self.k2)

    def _blocks(self, x: np.ndarray) -> np.ndarray:
        return x.reshape(self.coordinates, len(self.k2))

    def _force(self, x: np.ndarray, omega: float) -> tuple[np.ndarray, ...]:
        """``g``, ``∂g/∂x``, ``∂g/∂ẋ`` on the sample points, ``(n, S)`` and ``(n, n, S)`` (the
        last point's kept: Newton and the continuation ask for the residual and the Jacobian
        at the same ``x``)."""
        key = (x.tobytes(), float(omega))
        if key == self._last[0]:
            return self._last[1]
        xb = self._blocks(x)
        found = self.field.evaluate(xb @ self.basis.T, omega * (xb @ self.d_basis.T))
        self._last = (key, found)
        return found

    def residual(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        """The harmonics of ``q̈ + g(q, q̇) − f cos nωt`` (``n``: ``drive_harmonic``) for the
        unknowns ``x`` at ``ω``, with ``force`` in place of ``f`` when given: zero at a
        balance solution."""
        g, _, _ = self._force(x, omega)
        f = self.force if force is None else force
        return (-omega**2 * self.k2 * self._blocks(x) + g @ self.project.T).ravel() \
            - f * self.drive

    def jacobian(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        """``∂residual/∂x`` at ``(x, ω)``, from ``∂g/∂x`` and ``∂g/∂ẋ`` on the sample points."""
        _, gx, gv = self._force(x, omega)
        n, m = self.coordinates, len(self.k2)
        J = self.project @ (gx[..., None] * self.basis + omega * gv[..., None] * self.d_basis)
        J = J.transpose(0, 2, 1, 3).reshape(n * m, n * m)
        return J - np.diag(np.tile(omega**2 * self.k2, n))

    def d_omega(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        """``∂residual/∂ω`` at ``(x, ω)``, for the continuation in ω."""
        _, _, gv = self._force(x, omega)
        xb = self._blocks(x)
        dv = np.einsum("ijs,js->is", gv, xb @ self.d_basis.T)
        return (-2 * omega * self.k2 * xb + dv @ self.project.T).ravel()

    def amplitudes(self, x: np.ndarray, coordinate: int = 0
                   ) -> tuple[dict[int, float], dict[int, float]]:
        """``A_k``, ``B_k`` of ``x`` (``A_0`` the mean, when the orders hold it) of one
        coordinate (the first by default)."""
        xb = self._blocks(x)[coordinate]
        A = {int(k): float(a) for k, a in zip(self.orders, xb[: self.n_cos], strict=True)}
        B = {int(k): float(b) for k, b in zip(self.orders[self.orders > 0], xb[self.n_cos:],
                                              strict=True)}
        return A, B

    def vector(self, A: dict[int, float], B: dict[int, float]) -> np.ndarray:
        """The unknowns of ``A``, ``B`` (harmonics beyond the orders dropped, missing ones 0)."""
        return np.array([A.get(int(k), 0.0) for k in self.orders]
                        + [B.get(int(k), 0.0) for k in self.orders if k > 0])

    def refined(self, other: PolynomialBalance, x: np.ndarray) -> np.ndarray:
        """``other``'s unknowns ``x`` (the same equations, other harmonics) in this balance's
        layout: harmonics beyond its orders dropped, missing ones 0."""
        return np.concatenate([self.vector(*other.amplitudes(x, i))
                               for i in range(self.coordinates)])

    def first_harmonics(self, x: np.ndarray) -> np.ndarray:
        """``√(A_i1² + B_i1²)`` of each coordinate ``i``."""
        k1 = int(np.nonzero(self.orders == 1)[0][0])
        s1 = self.n_cos + int(np.nonzero(self.orders[self.orders > 0] == 1)[0][0])
        xb = self._blocks(x)
        return np.hypot(xb[:, k1], xb[:, s1])

    def first_harmonic(self, x: np.ndarray) -> float:
        """``√Σ_i (A_i1² + B_i1²)``: the first harmonic's size over every coordinate."""
        return float(np.linalg.norm(self.first_harmonics(x)))

    def state(self, x: np.ndarray, omega: float) -> np.ndarray:
        """``(x(0), ẋ(0))`` of a balance solution, every coordinate's: a shooting guess."""
        xb = self._blocks(x)
        return np.concatenate([xb[:, : self.n_cos].sum(axis=1),
                               omega * xb @ self.d_basis[0]])

    def linearization(self, x: np.ndarray, omega: float, samples: int
                      ) -> tuple[np.ndarray, np.ndarray]:
        """``∂g/∂x`` and ``∂g/∂ẋ`` along the balance orbit ``x`` at ``θ = ωt = 2πj/samples``:
        arrays ``(samples, n, n)``, the variational equation's coefficients."""
        basis, d_basis = self._bases(samples)
        xb = self._blocks(x)
        _, gx, gv = self.field.evaluate(xb @ basis.T, omega * (xb @ d_basis.T))
        return gx.transpose(2, 0, 1), gv.transpose(2, 0, 1)

    def solve(self, x: np.ndarray, omega: float, tol: float = 1e-13,
              max_iter: int = 50) -> tuple[np.ndarray, bool, float]:
        """Newton's method from ``x``: the solution, whether it converged, its residual."""
        return newton(lambda z: self.residual(z, omega), lambda z: self.jacobian(z, omega), x,
                      tol, max_iter)

    def solution(self, x: np.ndarray, omega: float, tol: float = 1e-13,
                 max_iter: int = 50) -> HarmonicBalance | None:
        """:meth:`solve` as a :class:`HarmonicBalance`, or ``None`` where Newton meets a
        singular Jacobian (exactly at a fold)."""
        try:
            x, converged, residual = self.solve(x, omega, tol, max_iter)
        except np.linalg.LinAlgError:
            return None
        return HarmonicBalance(self.harmonics, x, tuple(int(k) for k in self.orders), residual,
                               converged)


@dataclass(frozen=True)
class HarmonicBalance:
    """A solution of a :class:`PolynomialBalance` with ``harmonics`` harmonics: its unknowns
    ``x = (a_k …, b_k …)`` over ``orders`` (odd ``1 … 2N − 1`` for an odd force, else
    ``0 … 2N − 1``), Newton's residual and whether it converged."""

    harmonics: int
    x: np.ndarray
    orders: tuple[int, ...]
    residual: float
    converged: bool

    def amplitudes(self) -> tuple[dict[int, float], dict[int, float]]:
        """``A_k``, ``B_k`` of ``q = Σ A_k cos kωt + B_k sin kωt`` (``A_0`` the mean)."""
        n = len(self.orders)
        A = {k: float(a) for k, a in zip(self.orders, self.x[:n], strict=True)}
        B = {k: float(b) for k, b in zip((k for k in self.orders if k), self.x[n:],
                                         strict=True)}
        return A, B

    @property
    def coefficients(self) -> np.ndarray:
        """``c_n`` of ``e^{inωt}``, ``n = −M … M`` with ``M = 3(2N − 1)`` (the Fourier kernel's
        layout, :func:`algebra.series.laurent_from_fourier`)."""
        A, B = self.amplitudes()
        orders = np.array(self.orders)
        return laurent_from_fourier(3 * (2 * self.harmonics - 1), orders,
                                    np.array([A[k] for k in self.orders]),
                                    np.array([B.get(k, 0.0) for k in self.orders]))

    @property
    def r(self) -> float:
        """The first-harmonic amplitude ``√(A₁² + B₁²)``."""
        A, B = self.amplitudes()
        return math.hypot(A.get(1, 0.0), B.get(1, 0.0))

    def state(self, omega: float) -> np.ndarray:
        """``(q(0), q̇(0))``: a shooting guess."""
        A, B = self.amplitudes()
        return np.array([sum(A.values()), omega * sum(k * b for k, b in B.items())])

    def _repr_html_(self) -> str:
        A, B = self.amplitudes()
        return harmonics_table(f"harmonic balance, N = {self.harmonics} harmonics", A, B,
                               f"residual {self.residual:.1e}, "
                               f"{'converged' if self.converged else 'NOT converged'}")


def amplitude_bound(terms: dict[tuple[int, int], float], omega: float,
                    force: float) -> float | None:
    """A first-harmonic amplitude ``r`` beyond which ``q = r cos(ωt + φ)`` balances no drive of
    amplitude ``force``, doubled: ``None`` where none exists (the top degree even, or its
    terms not dominating: the response may grow without end).

    On ``q = r cos θ`` the first harmonic of ``q̈ + g`` is exactly
    ``P = (Σ_a κ_a c_a0 r^a − ω² r, −Σ_b κ_b c_0b (ωr)^b)`` over the odd pure powers
    (``κ_n = C(n, (n−1)/2)/2^(n−1)``, ¾ for n = 3; even pure powers have no first harmonic),
    plus at most ``2|c| r^a (ωr)^b`` from each mixed term ``c q^a q̇^b``: no orbit where
    ``|P| > force + Σ 2|c| r^a (ωr)^b``, i.e. beyond every root of the polynomial
    ``|P|² − (force + Σ …)²``; the largest modulus of its roots, complex ones included (a
    window where the two nearly touch counts).  The distortion of a true orbit by its higher
    harmonics is what the factor 2 leaves room for (a one-harmonic bound, not a proof)."""
    d = max(a + b for a, b in terms)
    if d % 2 == 0:
        return None

    def kappa(n: int) -> float:
        return math.comb(n, (n - 1) // 2) / 2 ** (n - 1)

    cos = [(a, kappa(a) * c) for (a, b), c in terms.items() if b == 0 and a % 2]
    sin = [(b, -kappa(b) * c * omega**b) for (a, b), c in terms.items() if a == 0 and b % 2]
    mixed = [(a + b, 2 * abs(c) * omega**b) for (a, b), c in terms.items() if a and b]
    P = np.polynomial.Polynomial
    pc, ps, pm = P([0.0, -omega**2]), P([0.0]), P([abs(force)])
    for n, c in cos:
        pc = pc + P([0.0] * n + [c])
    for n, c in sin:
        ps = ps + P([0.0] * n + [c])
    for n, c in mixed:
        pm = pm + P([0.0] * n + [c])
    H = (pc * pc + ps * ps - pm * pm).trim()
    if H.degree() < 2 * d or not H.coef[-1] > 0:
        return None
    roots = H.roots()
    return 2 * float(np.max(np.abs(roots))) if roots.size else 2e-6


@dataclass(frozen=True)
class DrivenForm:
    """A user's equation ``q̈ + g(q, q̇) = Σ f_i cos(ν_i t)`` once its values are given: ``g`` a
    polynomial, ``terms`` its exact coefficients ``{(a, b): c}`` of ``c q^a q̇^b`` (the linear
    part included); each drive ``(f, c, w)`` with ``ν = c·w``, ``c`` a positive rational and
    ``w`` a name left free (``None``: ``ν = c``)."""

    terms: dict[tuple[int, int], sp.Rational]
    drives: tuple[tuple[float, sp.Rational, sp.Symbol | None], ...]
    values: tuple[tuple[str, str], ...]

    def floats(self) -> dict[tuple[int, int], float]:
        """``terms`` as floats (a :class:`numerics.ForceTable`'s)."""
        return {k: float(c) for k, c in self.terms.items() if c != 0}


def driven_form(text: str, values: dict[str, str], name: str, method: str, why: str,
                free_frequency: bool) -> DrivenForm:
    """Map ``text`` onto :class:`DrivenForm` or refuse in one line naming what ``method``
    (``why``: its ansatz) needs: a force polynomial in q and q' with rational coefficients, no
    constant term, a linear term; the drive a sum of ``f cos(ν t)``; every parameter given,
    except, with ``free_frequency``, one name in the drives' frequencies."""
    from ..derive.models import oscillator

    osc = oscillator(text, values, name)
    q, v, t = osc.coordinate, osc.velocity, osc.equation.time
    if osc.parametric != 0:
        raise osc.refuse(method, f"{sp.sstr(osc.parametric)} depends on both t and {q}: {why}")
    force = sp.expand(osc.force)
    missing = sorted(str(s) for s in force.free_symbols - {q, v})
    if missing:
        raise osc.refuse(method, "give " + ", ".join(missing) + " a value (--param "
                         + " --param ".join(f"{m}=..." for m in missing) + ")")
    if not force.is_polynomial(q, v):
        raise osc.refuse(method, f"the force {sp.sstr(force)} is not a polynomial in {q} and "
                         f"{v}: {why}")
    poly = sp.Poly(force, q, v)
    if any(not c.is_Rational for c in poly.coeffs()):
        raise osc.refuse(method, f"the force {sp.sstr(force)}: its coefficients must be "
                         "rational numbers")
    terms = {k: sp.Rational(c) for k, c in zip(poly.monoms(), poly.coeffs(), strict=True)}
    if terms.get((0, 0)):
        raise osc.refuse(method, f"the constant force {terms[(0, 0)]} moves the equilibrium "
                         f"off {q} = 0; shift {q} to it")
    if not terms.get((1, 0)):
        raise osc.refuse(method, f"no linear term in {q}: q = 0 is no oscillator's "
                         "equilibrium")
    drive = sp.expand(osc.drive)
    if drive == 0:
        if values and oscillator(text, {}, name).drive != 0:
            raise osc.refuse(method, "the drive vanishes with the values given (a zero "
                             "amplitude): give it a nonzero one")
        raise osc.refuse(method, f"no drive: write it on the right, e.g. {q}'' + ... = "
                         "f*cos(w*t)")
    drives = []
    frequencies: set[sp.Symbol] = set()
    for term in sp.Add.make_args(drive):
        amplitude, wave = term.as_independent(t, as_Add=False)
        if not isinstance(wave, sp.cos):
            raise osc.refuse(method, f"the drive term {sp.sstr(term)} is not f*cos(w*t) (a "
                             "sine or another function of t: shift t or rewrite it)")
        c, rest = wave.args[0].as_independent(t, as_Add=False)
        if rest != t:
            raise osc.refuse(method, f"the drive's argument {sp.sstr(wave.args[0])} is not "
                             "w*t")
        number, symbols = c.as_coeff_Mul()
        symbol = None
        if symbols != 1:
            if not (free_frequency and isinstance(symbols, sp.Symbol)):
                need = ", ".join(sorted(str(s) for s in c.free_symbols))
                raise osc.refuse(method, f"give {need} a value (--param {need}=...): the "
                                 "drive frequencies must be numbers")
            symbol = symbols
            frequencies.add(symbol)
        missing = sorted(str(s) for s in amplitude.free_symbols)
        if missing:
            raise osc.refuse(method, "give " + ", ".join(missing) + " a value (--param "
                             + " --param ".join(f"{m}=..." for m in missing) + ")")
        if not (number.is_Rational and amplitude.is_Rational):
            raise osc.refuse(method, f"the drive term {sp.sstr(term)}: its amplitude and "
                             "frequency must be rational numbers")
        if not number > 0:
            raise osc.refuse(method, f"the drive term {sp.sstr(term)}: its frequency must be "
                             "> 0")
        drives.append((float(amplitude), number, symbol))
    if len(frequencies) > 1:
        raise osc.refuse(method, "the drives' frequencies name "
                         + ", ".join(sorted(map(str, frequencies))) + "; give them values")
    return DrivenForm(terms, tuple(drives), tuple((str(k), str(val)) for k, val in osc.values))
