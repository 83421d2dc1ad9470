"""The slow flow of a system's modes in internal resonance, by first-order averaging, exact.

Where the linear frequencies are commensurate (``ω_j = n ω_i``, the small divisors that make
``nnm`` refuse), the modes exchange energy instead of each carrying a normal mode. In the
resonant modes' coordinates ``x = Σ_k φ_k q_k`` (the other modes unexcited at this order),
``q_k'' + ω_k² q_k = f_k(q)``, ``f_k = −ψ_k·g(Σ φ q)`` with the lowest-degree force ``g`` and
the left eigenvectors ``ψ_k`` (``ψ_k·φ_k = 1``).  With ``q_k = a_k cos θ_k``,
``q_k' = −a_k ω_k sin θ_k`` and ``θ_k = ω_k t + φ_k``, van der Pol's variables obey

    a_k' = −(1/ω_k) f_k sin θ_k,      a_k φ_k' = −(1/ω_k) f_k cos θ_k,

and averaging over the fast angles keeps exactly the terms ``e^{i Σ m_k θ_k}`` with
``Σ m_k ω_k = 0``: the resonant combinations of the slow phases.  Each average is computed in
``z_k = e^{iθ_k}`` as a Laurent polynomial, exact (ω_k in Q or Q(√λ)).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import sympy as sp

from ..errors import InputError
from .system import System


@dataclass(frozen=True)
class ResonantFlow:
    """The first-order slow flow of the modes ``modes`` (1-based) in internal resonance:
    ``da_k/dt = amplitude[k]``, ``dφ_k/dt = phase[k]`` in the symbols ``a``, ``phi`` (exact
    SymPy), the modes' exact ``ω`` and shapes, and the resonances named."""

    system: System
    modes: tuple[int, ...]
    omega: tuple[sp.Expr, ...]
    shapes: tuple[tuple[sp.Expr, ...], ...]
    a: tuple[sp.Symbol, ...]
    phi: tuple[sp.Symbol, ...]
    amplitude: tuple[sp.Expr, ...]
    phase: tuple[sp.Expr, ...]
    resonances: tuple[str, ...]
    degree: int  # the force's lowest degree: the flow is of order (amplitude)^(degree − 1)


def resonant_modes(system: System) -> tuple[list[int], list[str]]:
    """The modes linked by exact ratios ``ω_j/ω_i = n`` (n ≥ 2), and the resonances named."""
    lams = system.modes()
    found: set[int] = set()
    names = []
    for i, j in itertools.combinations(range(len(lams)), 2):
        ratio = sp.nsimplify(lams[j] / lams[i])
        root = sp.sqrt(ratio)
        if ratio.is_Rational and root.is_Integer and root >= 2:
            found |= {i, j}
            names.append(f"1:{root} between mode {i + 1} (ω0 = {sp.sqrt(lams[i])}) and mode "
                         f"{j + 1} (ω0 = {sp.sqrt(lams[j])})")
    return sorted(found), names


def _shapes(system: System, lam: sp.Expr) -> tuple[sp.Matrix, sp.Matrix]:
    """The right and left eigenvectors of ``M⁻¹K`` at ``lam``, with ``ψ·φ = 1``."""
    L = system.stiffness
    right = (L - lam * sp.eye(system.size)).nullspace(simplify=True)[0]
    left = (L.T - lam * sp.eye(system.size)).nullspace(simplify=True)[0]
    return right, left / sp.simplify((left.T * right)[0])


def resonant_flow(system: System, order: int = 1) -> ResonantFlow:
    """The first-order averaged flow of the resonant modes of ``system`` (``order`` 1 only)."""
    if order != 1:
        raise InputError(f"--order {order}: a system's resonant slow flow is derived to the "
                         "first order (where the resonance enters); higher orders are not "
                         "built")
    if not system.conservative:
        raise InputError(f"system {system.text!r}: a velocity-dependent force; the resonant "
                         "slow flow takes conservative systems")
    if all(f == 0 for f in system.force):
        raise InputError(f"system {system.text!r}: no nonlinear term: a linear system's modes "
                         "are independent and exchange no energy, so there is no slow flow to "
                         "average; lindstedt nnm SYSTEM --mode M gives each mode")
    modes, names = resonant_modes(system)
    if not modes:
        raise InputError(f"system {system.text!r}: no internal resonance (no ω0 an integer "
                         "multiple of another); lindstedt nnm SYSTEM --mode M gives each mode")
    lams = system.modes()
    omega = [sp.sqrt(lams[k]) for k in modes]
    base = min(omega)
    ratios = [sp.nsimplify(w / base) for w in omega]
    degree = min(len(powers) and sum(powers) for f in system.force if f != 0
                 for powers in sp.Poly(f, *system.coordinates).monoms())
    shapes, lefts = zip(*(_shapes(system, lams[k]) for k in modes), strict=True)
    n = len(modes)
    a = sp.symbols(f"a1:{n + 1}", positive=True)
    phi = sp.symbols(f"phi1:{n + 1}", real=True)
    z = sp.symbols(f"z1:{n + 1}")
    q = [a[k] * (z[k] + 1 / z[k]) / 2 for k in range(n)]
    x = sp.zeros(system.size, 1)
    for k in range(n):
        x += shapes[k] * q[k]
    lowest = [sum(t for t in sp.Add.make_args(sp.expand(f)) if sp.Poly(t, *system.coordinates)
                  .total_degree() == degree) for f in system.force]
    g = sp.Matrix([f.xreplace(dict(zip(system.coordinates, x, strict=True))) for f in lowest])

    def average(expr: sp.Expr) -> sp.Expr:
        """The fast-angle mean of a Laurent polynomial in the z_k: the resonant terms, with
        z_k → e^{iφ_k}, as a real expression."""
        poly = sp.Poly(sp.expand(expr * sp.Mul(*(zk**(3 * degree) for zk in z))), *z)
        kept = sp.S.Zero
        for powers, c in poly.terms():
            m = [p - 3 * degree for p in powers]
            if sum(mk * r for mk, r in zip(m, ratios, strict=True)) == 0:
                kept += c * sp.exp(sp.I * sum(mk * p for mk, p in zip(m, phi, strict=True)))
        return sp.simplify(sp.expand_complex(sp.expand(kept)))

    amplitude, phase = [], []
    for k in range(n):
        f = -(lefts[k].T * g)[0]
        sin_k = (z[k] - 1 / z[k]) / (2 * sp.I)
        cos_k = (z[k] + 1 / z[k]) / 2
        amplitude.append(sp.simplify(-average(f * sin_k) / omega[k]))
        phase.append(sp.simplify(-average(f * cos_k) / (omega[k] * a[k])))
    return ResonantFlow(system, tuple(k + 1 for k in modes), tuple(omega),
                        tuple(tuple(s) for s in shapes), a, phi, tuple(amplitude), tuple(phase),
                        tuple(names), degree)


def _combinations(flow: ResonantFlow) -> set[sp.Expr]:
    """The resonant combinations ``Σ m_k φ_k`` the flow depends on (up to sign)."""
    found = set()
    for e in (*flow.amplitude, *flow.phase):
        for f in e.atoms(sp.sin, sp.cos):
            arg = f.args[0]
            found.add(arg if sp.Poly(arg, *flow.phi).coeffs()[0] > 0 else -arg)
    return found


def coupled_modes(flow: ResonantFlow) -> list[tuple[sp.Expr, sp.Expr]]:
    """The phase-locked solutions (the coupled modes) of a two-mode flow with one resonant
    combination ``γ``: pairs ``(γ, a₂/a₁)`` where every ``a_k' = 0`` and ``γ' = 0``, exact
    (the flow is homogeneous in the amplitudes: a ratio fixes a ray of them).  Empty where
    more modes or combinations take part (not derived)."""
    combos = _combinations(flow)
    if len(flow.modes) != 2 or len(combos) != 1:
        return []
    (combo,) = combos
    gamma = sp.Symbol("gamma", real=True)
    m = [combo.coeff(p) for p in flow.phi]
    if abs(m[1]) != 1:
        return []
    put = {flow.phi[1]: (gamma - m[0] * flow.phi[0]) / m[1], flow.a[0]: sp.Integer(1)}
    rates = [sp.simplify(e.xreplace(put)) for e in (*flow.amplitude, *flow.phase)]
    dgamma = sp.simplify(m[0] * rates[2] + m[1] * rates[3])
    ratio = sp.Symbol("r", positive=True)
    out = []
    for g in (sp.Integer(0), sp.pi):
        if all(sp.simplify(r.xreplace({gamma: g})) == 0 for r in rates[:2]):
            locked = sp.numer(sp.together(dgamma.xreplace({gamma: g, flow.a[1]: ratio})))
            roots = _real_roots(locked, ratio) if locked.has(ratio) else []
            out += [(g, root) for root in roots if root > 0]  # exact: surds or CRootOf
    return out


def _real_roots(expr: sp.Expr, x: sp.Symbol) -> list[sp.Expr]:
    """The real roots of the polynomial ``expr`` in ``x``, exact: SymPy's isolation over the
    rationals, else (coefficients in surds: a decimal system's irrational ω₀) its solver."""
    poly = sp.Poly(expr, x)
    if poly.domain.is_ZZ or poly.domain.is_QQ:
        return poly.real_roots()
    return [r for r in sp.solve(expr, x) if r.is_real]


def force_ratio(flow: ResonantFlow, start: tuple[float, ...], limit: float = 1.0
                ) -> tuple[float, float]:
    """How weak the nonlinearity is at amplitudes ``start``: ``(log₁₀ ρ, λ)`` with
    ``ρ = max_i Σ_terms |c| Π_j X_j^{p_j} / (ω_min² max_i X_i)`` — every nonlinear term of
    equation i at the coordinates' peaks ``X_i = Σ_k |φ_k,i| a_k`` against the slowest
    resonant mode's linear restoring force — and ``λ`` the factor of ``start`` where ``ρ``
    reaches ``limit`` (ρ grows with λ: every term has degree ≥ 2).  In logarithms: any finite
    amplitude, no overflow.

    >>> from lindstedt.derive.system import parse_system
    >>> flow = resonant_flow(parse_system("x'' + x + x*y = 0; y'' + 4*y + x**2 = 0"))
    >>> [round(v, 12) for v in force_ratio(flow, (0.5, 0.25))]  # x² = 0.25 against 1·0.5
    [-0.301029995664, 2.0]
    """
    system = flow.system
    peaks = [sum(abs(float(shape[i])) * a for shape, a in zip(flow.shapes, start, strict=True))
             for i in range(system.size)]
    logs = [math.log(x) if x > 0 else -math.inf for x in peaks]
    linear = 2 * math.log(float(min(flow.omega))) + max(logs)
    # each equation's terms as (log of its size at start − the linear force's, degree − 1)
    equations = []
    for f in system.force:
        terms = []
        for powers, c in sp.Poly(f, *system.coordinates).terms():
            if all(p == 0 or x > 0 for p, x in zip(powers, peaks, strict=True)):
                size = math.log(abs(float(c))) + sum(p * x for p, x in zip(powers, logs,
                                                                             strict=True)
                                                     if p)
                terms.append((size - linear, sum(powers) - 1))
        if terms:
            equations.append(terms)

    def log_ratio(shift: float) -> float:
        """ln ρ at ``start · e^shift`` (a log-sum-exp per equation)."""
        worst = -math.inf
        for terms in equations:
            logs_t = [size + degree * shift for size, degree in terms]
            top = max(logs_t)
            worst = max(worst, top + math.log(sum(math.exp(v - top) for v in logs_t)))
        return worst

    if not equations:
        return -math.inf, math.inf
    lo, hi = -2000.0, 2000.0  # ln λ: ρ is increasing in it; 60 halvings leave 4e-15
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if log_ratio(mid) < math.log(limit) else (lo, mid)
    return log_ratio(0.0) / math.log(10), math.exp((lo + hi) / 2)
