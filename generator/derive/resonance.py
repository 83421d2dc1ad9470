"""A system's modes in internal resonance: which modes (``ω_j = n ω_i``, the small divisors
that make ``nnm`` refuse), their right and left shapes, and of their slow flow
(:func:`derive.averaging.slow_flow`, a :class:`~derive.averaging.SlowFlow` of the resonant
modes) the phase-locked coupled modes and how weak the nonlinearity is at given amplitudes.
"""

from __future__ import annotations

import itertools
import math

import sympy as sp

from .system import System


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


def _combinations(flow) -> set[sp.Expr]:
    """The resonant combinations ``Σ m_k φ_k`` the flow depends on (up to sign)."""
    found = set()
    for e in (*flow.amplitude, *flow.phase):
        for f in e.atoms(sp.sin, sp.cos):
            arg = f.args[0]
            found.add(arg if sp.Poly(arg, *flow.phi).coeffs()[0] > 0 else -arg)
    return found


def coupled_modes(flow) -> list[tuple[sp.Expr, sp.Expr]]:
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


def force_ratio(flow, start: tuple[float, ...], limit: float = 1.0
                ) -> tuple[float, float]:
    """How weak the nonlinearity is at amplitudes ``start``: ``(log₁₀ ρ, λ)`` with
    ``ρ = max_i Σ_terms |c| Π_j X_j^{p_j} / (ω_min² max_i X_i)`` — every nonlinear term of
    equation i at the coordinates' peaks ``X_i = Σ_k |φ_k,i| a_k`` against the slowest
    resonant mode's linear restoring force — and ``λ`` the factor of ``start`` where ``ρ``
    reaches ``limit`` (ρ grows with λ: every term has degree ≥ 2).  In logarithms: any finite
    amplitude, no overflow.

    >>> from lindstedt.derive.averaging import slow_flow
    >>> from lindstedt.derive.system import parse_system
    >>> flow = slow_flow(parse_system("x'' + x + x*y = 0; y'' + 4*y + x**2 = 0"), 1)
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
