"""The slow flow of ``q̈ + q = ε f(q, q̇) (+ ε F cos ωt)``: averaging to any order.

Van der Pol's variables ``q = u cos τ + v sin τ``, ``q' = −u sin τ + v cos τ`` put the equation
in the standard form of averaging, ``x' = Σ ε^k F_k(x, τ)`` with ``x = (u, v)`` and
``F_k = (−g_k sin τ, g_k cos τ)`` (``g_k`` the ε^k part of the right side).  A near-identity
transformation ``x = y + Σ_{j≥1} ε^j w_j(y, τ)`` with mean-free ``w_j`` (Sanders, Verhulst &
Murdock, *Averaging Methods*, §2.9; the Krylov–Bogoliubov–Mitropolsky convention)
turns it into the autonomous slow flow ``y' = Σ ε^k G_k(y)``: the order-ε^k part of
``∂_τ W + G + DW·G = F(y + W, τ)`` reads

    ∂_τ w_k + G_k = [F(y + W, τ)]_k − Σ_{i+j=k} Dw_i · G_j,

whose mean over τ is ``G_k`` and whose rest, integrated, is ``w_k`` (for k = 2 the book's
second-order averaging, §2.9).  Every average and integral runs in the exact Fourier kernel
(:class:`series.Trig` over ``QQ[u, v, params]``): in these variables ``F`` is a polynomial, free
of the ``1/r`` of the polar form.  The polar flow (``u = r cos φ``, ``v = −r sin φ``, so
``q = r cos(τ + φ)``)

    dr/dt = Σ ε^k R_k(r, φ),   dφ/dt = Σ ε^k Φ_k(r, φ)

follows exactly from ``G`` (``r' = (u u' + v v')/r``, ``φ' = (v u' − u v')/r²``).  Beyond
the first order the flow depends on the transformation's convention (mean-free here; Nayfeh's
multiple scales or a stroboscopic choice give other, equivalent flows); what an orbit does does
not: a cycle's frequency, the transients once mapped back with ``w_j``.

Drive: a term ``ε F cos ωt`` (or ``sin ωt``) is taken near resonance, ``ω = 1 + εσ``, in the
time ``τ = ωt`` (``ω² q'' + q = ε f(q, ω q') + ε F cos τ``, with ``1/ω²`` expanded in ε), so the
slow flow lives in the frame rotating with the drive and its fixed points are the steady
states; it is reported in ``t`` (``d/dt = ω d/dτ``, truncated at the same order).

A system's modes in internal resonance (``ω_j = n ω_i``, the small divisors that make ``nnm``
refuse) are the same averaging over one angle.  Their frequencies are integer multiples
``r_k`` of a base ``ω_b = ω_min/L`` (L the lcm of the ratios' denominators), so in ``τ = ω_b t``
every fast angle is ``r_k τ``.  In the resonant modes' coordinates ``x = Σ_k φ_k q_k`` (the
other modes unexcited at this order), ``q_k'' + r_k² q_k = ε g_k`` with
``g_k = −ψ_k·g(Σ φ_j q_j)/ω_b²``, ``g`` the force's lowest degree d and ``ψ_k`` the left
eigenvectors of ``M⁻¹K`` (``ψ_k·φ_k = 1``); the bookkeeping ε is the amplitude scale to the
power d − 1, absorbed into the amplitudes.  Van der Pol's variables per mode,
``q_k = u_k cos r_kτ + v_k sin r_kτ``, ``q_k' = r_k(−u_k sin r_kτ + v_k cos r_kτ)``, give the
standard form ``u_k' = −(ε/r_k) g_k sin r_kτ``, ``v_k' = (ε/r_k) g_k cos r_kτ``: 2m components
over ``QQ[u_1, v_1, …, u_m, v_m, params]`` (ω₀² rational: the shapes ``φ, ψ`` and ``g_k`` are),
averaged as above with multi-indices in the Taylor terms.  The mean over τ keeps exactly the
terms ``e^{i Σ m_k θ_k}`` with ``Σ m_k ω_k = 0``, the resonant combinations of the slow phases
(Nayfeh & Mook, *Nonlinear Oscillations*, §6.5).  Per mode ``u_k = a_k cos φ_k``,
``v_k = −a_k sin φ_k`` (``q_k = a_k cos(ω_k t + φ_k)``), in ``t`` (``d/dt = ω_b d/dτ``).  A
system's flow is of the first order, where the resonance enters: the next needs the
non-resonant modes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp
from sympy.polys.domains import QQ

from ..algebra.series import Ground, MPoly, Trig
from ..errors import InputError
from ..limits import SLOW_FLOW_MAX_ORDER as MAX_ORDER
from ..limits import check_int
from .models import Oscillator

if TYPE_CHECKING:
    from .system import System

U, V = sp.Symbol("_u"), sp.Symbol("_v")  # van der Pol's variables ("_": no user name clashes)
R, PHI = sp.Symbol("r", positive=True), sp.Symbol("phi")
SIGMA = sp.Symbol("sigma")  # the detuning of a drive, ω = 1 + ε σ
EPS = sp.Symbol("eps")
METHOD = "the slow flow"
RESERVED = frozenset({"r", "phi", "u", "v", "x"})
# NOTE: the polar and Cartesian variables and the emitted kernels' state vector x.


@dataclass(frozen=True)
class SlowFlow:
    """The averaged equations of one oscillator ``q̈ + q = ε f`` to order ``order``, or of a
    system's m modes in internal resonance to the first order (see the module docstring).

    ``radial[k·order + j − 1]``, ``phase[k·order + j − 1]``: ``R_j`` and ``Φ_j`` of mode k + 1,
    ``da_k/dt = Σ_j ε^j R_j``, ``dφ_k/dt = Σ_j ε^j Φ_j`` in the symbols ``a``, ``phi`` (SymPy,
    exact; one oscillator: ``radial[j−1]``, ``phase[j−1]`` in ``r``, ``phi``); ``small``: ε's
    symbol, 1 for a system (absorbed into the amplitudes); ``cartesian[j−1]``: ``G_j``, the flow
    of ``(u_1, v_1, …)`` (one oscillator: ``(U_j, V_j)`` in ``(_u, _v)``); ``transform[j−1]``:
    ``w_j`` as SymPy expressions in ``_u, _v`` and ``tau`` (j < order), the near-identity
    transformation back to ``q``.  A system's record adds the modes (1-based), their exact ω₀,
    shapes, the resonances named and the force's lowest degree d (the flow is of order
    (amplitude)^(d − 1)).
    """

    name: str
    source: str
    order: int
    coordinate: str
    parameters: tuple[sp.Symbol, ...]
    driven: bool
    radial: tuple[sp.Expr, ...]
    phase: tuple[sp.Expr, ...]
    cartesian: tuple[tuple[sp.Expr, ...], ...]
    transform: tuple[tuple[sp.Expr, sp.Expr], ...]
    a: tuple[sp.Symbol, ...] = (R,)
    phi: tuple[sp.Symbol, ...] = (PHI,)
    small: sp.Expr = EPS
    system: System | None = None
    modes: tuple[int, ...] = (1,)
    omega: tuple[sp.Expr, ...] = (sp.S.One,)
    shapes: tuple[tuple[sp.Expr, ...], ...] = ((sp.S.One,),)
    resonances: tuple[str, ...] = ()
    degree: int = 0  # a system's force's lowest degree (0: one oscillator, ε explicit)

    @cached_property
    def amplitude(self) -> tuple[sp.Expr, ...]:
        """``da_k/dt`` of each mode (one oscillator: ``(dr/dt,)``)."""
        return self._rates(self.radial)

    @cached_property
    def rates(self) -> tuple[sp.Expr, ...]:
        """``(da_1/dt, …, da_m/dt, dφ_1/dt, …, dφ_m/dt)``; one oscillator ``(dr/dt, dφ/dt)``
        in ``r, phi, eps`` and the parameters."""
        return (*self.amplitude, *self._rates(self.phase))

    def _rates(self, parts: tuple[sp.Expr, ...]) -> tuple[sp.Expr, ...]:
        K = self.order
        return tuple(sp.Add(*(self.small ** (j + 1) * parts[k * K + j] for j in range(K)))
                     for k in range(len(self.a)))


def slow_flow(problem: Oscillator | System, order: int) -> SlowFlow:
    """The slow flow of ``problem`` to order ``order``: one oscillator
    (``q'' + q = eps*f(q, q')``, optionally ``+ eps*F*cos(w*t)``) or a system's modes in
    internal resonance (order 1); a one-line :class:`InputError` names what does not fit."""
    if isinstance(problem, Oscillator):
        check_int(order, 1, MAX_ORDER,
                  f"order {order!r}: the slow flow is derived to orders 1 … {MAX_ORDER}")
        setup = _oscillator_right_side(problem, order)
    else:
        setup = _resonant_right_side(problem, order)
    ground = _ground((*setup.slow, *setup.params))
    F = _standard_form(setup, ground, order)
    G, W = _average(F, ground, order)
    to_sp = ground.to_sympy
    Gs = [tuple(sp.expand(to_sp(_mean(c))) for c in Gk) for Gk in G]
    if setup.system is not None:
        return _resonant_record(setup, Gs)
    driven = setup.driven
    if driven:  # τ = ωt: d/dt = (1 + εσ) d/dτ, truncated
        Gs = [tuple(sp.expand(a + (SIGMA * b if k else 0)) for a, b in
                    zip(Gs[k], Gs[k - 1] if k else (0, 0), strict=True))
              for k in range(order)]
    radial, phase = zip(*(_polar(Gk) for Gk in Gs), strict=True)
    osc = setup.oscillator
    if not driven and any(e.has(PHI) for e in radial + phase):
        raise AssertionError(f"{osc.name}: an autonomous slow flow depends on φ")
    tau = sp.Symbol("tau")
    transform = tuple(tuple(_trig_expr(c, ground, tau) for c in Wj) for Wj in W[: order - 1])
    return SlowFlow(name=osc.name, source=osc.equation.text, order=order,
                    coordinate=str(osc.coordinate), parameters=setup.params, driven=driven,
                    radial=tuple(radial), phase=tuple(phase),
                    cartesian=tuple(Gs), transform=transform)


@dataclass(frozen=True)
class _Setup:
    """The right sides ``g[k][i]`` (the ε^k part of mode i's) as polynomials in ``qs``,
    ``qps`` (``q_i``, ``dq_i/dτ``), ``_cos``, ``_sin`` (of τ: a drive), the modes' multiples
    ``ratios`` of the base frequency, the slow variables ``(u_1, v_1, …)`` and parameters."""

    g: dict[int, tuple[sp.Expr, ...]]
    qs: tuple[sp.Symbol, ...]
    qps: tuple[sp.Symbol, ...]
    ratios: tuple[int, ...]
    slow: tuple[sp.Symbol, ...]
    params: tuple[sp.Symbol, ...]
    driven: bool = False
    oscillator: Oscillator | None = None
    system: System | None = None
    base: sp.Expr = sp.S.One  # ω_b
    modes: tuple[int, ...] = ()
    omega: tuple[sp.Expr, ...] = ()
    shapes: tuple[tuple[sp.Expr, ...], ...] = ()
    resonances: tuple[str, ...] = ()
    degree: int = 0


def _oscillator_right_side(osc: Oscillator, order: int) -> _Setup:
    g, params, driven = _right_side(osc, order)
    return _Setup({k: (gk,) for k, gk in g.items()}, (sp.Symbol("_q"),), (sp.Symbol("_qp"),),
                  (1,), (U, V), params, driven, oscillator=osc)


def _resonant_right_side(system: System, order: int) -> _Setup:
    """A system's resonant modes in the base time ``τ = ω_b t``: ``g_k = −ψ_k·g/ω_b²`` of the
    lowest-degree force ``g`` at ``x = Σ φ_j q_j``, or a one-line refusal."""
    from .resonance import _shapes, resonant_modes  # NOTE: here, not above: SciPy's sparse
    # matrices (derive.system) would load with every one-oscillator command

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
    lams = system.modes()
    if not modes:
        shared = next((k for k in range(1, len(lams)) if lams[k] == lams[k - 1]), None)
        if shared is not None:
            raise InputError(f"system {system.text!r}: modes {shared} and {shared + 1} share "
                             f"ω0² = {lams[shared]} (a 1:1 internal resonance): its slow flow "
                             "is not built (the mode shapes are not unique); slowflow takes "
                             "modes whose ω0 are in ratios 1:n, n ≥ 2")
        raise InputError(f"system {system.text!r}: no internal resonance (no ω0 an integer "
                         "multiple of another); lindstedt nnm SYSTEM --mode M gives each mode")
    for k in modes:
        if not lams[k].is_Rational:
            raise InputError(f"system {system.text!r}: mode {k + 1}'s ω0² = {lams[k]} is "
                             "irrational; the resonant slow flow is averaged exactly where "
                             "each resonant ω0² is rational")
    low = min(lams[k] for k in modes)
    squares = [lams[k] / low for k in modes]
    roots = [sp.sqrt(s) for s in squares]
    if not all(r.is_Rational for r in roots):
        raise InputError(f"system {system.text!r}: its resonant modes form groups of "
                         "incommensurate frequencies (ω0 ratios "
                         f"{', '.join(str(r) for r in roots)}); the slow flow is averaged over "
                         "one angle, where the resonant ω0 are rational multiples of one another")
    L = math.lcm(*(int(r.q) for r in roots))
    ratios = tuple(int(r * L) for r in roots)
    base2 = low / L**2  # ω_b²
    degree = min(len(powers) and sum(powers) for f in system.force if f != 0
                 for powers in sp.Poly(f, *system.coordinates).monoms())
    shapes, lefts = zip(*(_shapes(system, lams[k]) for k in modes), strict=True)
    m = len(modes)
    qs = sp.symbols(f"_q1:{m + 1}")
    x = sp.zeros(system.size, 1)
    for k in range(m):
        x += shapes[k] * qs[k]
    lowest = [sp.Add(*(t for t in sp.Add.make_args(sp.expand(f))
                       if sp.Poly(t, *system.coordinates).total_degree() == degree))
              for f in system.force]
    force = sp.Matrix([f.xreplace(dict(zip(system.coordinates, x, strict=True)))
                       for f in lowest])
    g = tuple(sp.expand(-(lefts[k].T * force)[0] / base2) for k in range(m))
    params = tuple(sorted(set().union(*(e.free_symbols for e in g)) - set(qs), key=str))
    slow = tuple(s for k in range(1, m + 1) for s in sp.symbols(f"_u{k} _v{k}"))
    return _Setup({1: g}, qs, sp.symbols(f"_qp1:{m + 1}"), ratios, slow, params,
                  system=system, base=sp.sqrt(base2), modes=tuple(k + 1 for k in modes),
                  omega=tuple(sp.sqrt(lams[k]) for k in modes),
                  shapes=tuple(tuple(s) for s in shapes), resonances=tuple(names),
                  degree=degree)


def _resonant_record(setup: _Setup, Gs: list[tuple[sp.Expr, ...]]) -> SlowFlow:
    """A system's first-order flow in ``t`` and, per mode, in amplitude and phase: with
    ``u = a cos φ``, ``v = −a sin φ``, ``ω_k da_k/dt = −⟨f_k sin θ_k⟩`` and
    ``ω_k a_k dφ_k/dt = −⟨f_k cos θ_k⟩`` (``f_k = ω_b² g_k``), the means as sums of
    ``e^{i Σ m_j φ_j}`` made real."""
    m = len(setup.modes)
    a = sp.symbols(f"a1:{m + 1}", positive=True)
    phi = sp.symbols(f"phi1:{m + 1}", real=True)
    E = [sp.exp(sp.I * p) for p in phi]
    cos = [(e + 1 / e) / 2 for e in E]
    sin = [(e - 1 / e) / (2 * sp.I) for e in E]
    polar = {}
    for k in range(m):
        polar[setup.slow[2 * k]] = a[k] * cos[k]
        polar[setup.slow[2 * k + 1]] = -a[k] * sin[k]
    (G,) = Gs
    square = setup.base**2
    amplitude, phase = [], []
    for k in range(m):
        Uk, Vk = (e.xreplace(polar) for e in G[2 * k: 2 * k + 2])
        r = setup.ratios[k]
        mean_sin = -r * square * (cos[k] * Uk - sin[k] * Vk)  # ⟨f_k sin θ_k⟩
        mean_cos = r * square * (sin[k] * Uk + cos[k] * Vk)  # ⟨f_k cos θ_k⟩
        real_sin, real_cos = (sp.simplify(sp.expand_complex(sp.expand(e)))
                              for e in (mean_sin, mean_cos))
        amplitude.append(sp.simplify(-real_sin / setup.omega[k]))
        phase.append(sp.simplify(-real_cos / (setup.omega[k] * a[k])))
    system = setup.system
    return SlowFlow(name="system", source=system.text, order=1,
                    coordinate=", ".join(str(c) for c in system.coordinates),
                    parameters=setup.params, driven=False, radial=tuple(amplitude),
                    phase=tuple(phase),
                    cartesian=(tuple(sp.expand(setup.base * e) for e in G),), transform=(),
                    a=a, phi=phi, small=sp.Integer(1), system=system, modes=setup.modes,
                    omega=setup.omega, shapes=setup.shapes, resonances=setup.resonances,
                    degree=setup.degree)


def _right_side(osc: Oscillator, order: int
                ) -> tuple[dict[int, sp.Expr], tuple[sp.Symbol, ...], bool]:
    """``{k: g_k}``: the ε^k part of ``q'' + q = g(q, q', cos τ, sin τ)`` (``q'`` the τ
    derivative, ``τ = ωt``), with the symbolic parameters (σ added for a drive)."""
    eq = osc.equation
    q, qdot, qddot = eq.derivatives[:3]
    eps = eq.small
    form = "write it as q'' + q = eps*f(q, q') [+ eps*F*cos(w*t)]"
    if eps is None:
        raise osc.refuse(METHOD, f"no small parameter eps: {form}")
    if osc.parametric != 0:
        raise osc.refuse(METHOD, "it is parametrically excited (terms in both t and q)")
    mass = sp.expand(eq.expression).coeff(qddot)
    if mass != 1:
        raise osc.refuse(METHOD, f"the coefficient of {qddot} is {mass}, not 1: {form}")
    c, s = sp.Symbol("_cos"), sp.Symbol("_sin")
    drive, omega = _drive(osc, c, s)
    params = tuple(sorted(set(osc.parameters) - ({omega} if omega is not None else set())
                          | ({SIGMA} if drive != 0 else set()), key=str))
    taken = sorted({str(p) for p in params} & RESERVED)
    if taken:
        raise osc.refuse(METHOD, f"the parameter name(s) {', '.join(taken)}: r, phi, u, v and "
                         "x are the slow flow's own variables; rename them")
    if drive != 0 and omega is not None and SIGMA in set(osc.parameters):
        raise osc.refuse(METHOD, "the name sigma is the detuning (w = 1 + eps*sigma); rename "
                         "the parameter")
    h = sp.expand(q - osc.force)
    if not h.is_polynomial(q, qdot, eps):
        raise osc.refuse(METHOD, "f(q, q') must be a polynomial")
    if sp.expand(h.subs(eps, 0)) != 0:
        raise osc.refuse(METHOD, f"at eps = 0 it is not q'' + q = 0 (left over: "
                         f"{sp.sstr(sp.expand(h.subs(eps, 0)))}): {form}")
    qp = sp.Symbol("_qp")  # dq/dτ
    sigma_eps = eps * SIGMA if drive != 0 else sp.Integer(0)
    w = 1 + sigma_eps
    inverse = sp.Add(*((n + 1) * (-sigma_eps) ** n for n in range(order + 1)))  # 1/ω²
    g = sp.expand(q * (1 - inverse) + (h.xreplace({qdot: w * qp}) + drive) * inverse)
    parts = sp.Poly(g, eps).as_dict() if g != 0 else {}
    out = {k: gk for (k,), gk in sorted(parts.items()) if 1 <= k <= order}
    for k, gk in out.items():
        try:
            sp.Poly(gk, q, qp, c, s, *params, domain=QQ)
        except (sp.PolynomialError, sp.CoercionFailed, sp.GeneratorsNeeded):
            raise osc.refuse(METHOD, f"the coefficient {sp.sstr(gk)} of eps^{k} is not a "
                             "polynomial with rational coefficients in the parameters (give "
                             "values with --param)") from None
    return ({k: gk.xreplace({q: sp.Symbol("_q")}) for k, gk in out.items()}, params,
            drive != 0)


def _drive(osc: Oscillator, c: sp.Symbol, s: sp.Symbol) -> tuple[sp.Expr, sp.Symbol | None]:
    """The drive with ``cos(ωt) → _cos``, ``sin(ωt) → _sin`` (``τ = ωt``) and ``ω``'s symbol
    (None for ω = 1 or no drive); a drive of another form is refused."""
    t, eps = osc.equation.time, osc.equation.small
    drive = sp.expand(osc.drive)
    if drive == 0:
        return drive, None
    trig = {f for f in drive.atoms(sp.cos, sp.sin) if f.has(t)}
    arguments = {f.args[0] for f in trig}
    if len(arguments) != 1:
        raise osc.refuse(METHOD, "the drive must be F*cos(w*t) (one frequency w, near 1)")
    (arg,) = arguments
    omega = sp.simplify(arg / t)
    if omega.has(t) or not (omega == 1 or (omega.is_Symbol and omega != eps)):
        raise osc.refuse(METHOD, f"the drive's frequency is {sp.sstr(omega)}: write "
                         "cos(w*t) with w a parameter (taken as w = 1 + eps*sigma) or cos(t)")
    out = drive.xreplace({sp.cos(arg): c, sp.sin(arg): s})
    if out.has(t) or not out.is_polynomial(c, s) or sp.expand(out.subs(eps, 0)) != 0:
        raise osc.refuse(METHOD, f"the drive {sp.sstr(drive)} is not eps*(F cos(w*t) + G "
                         "sin(w*t)) (the forcing must be small, of order eps)")
    return out, (omega if omega != 1 else None)


def _ground(symbols: tuple[sp.Symbol, ...]) -> Ground:
    """``QQ[u, v, params]``, the coefficient ring of every Fourier sum of the derivation."""
    return Ground(QQ.poly_ring(*symbols))


def _harmonic(ground: Ground, r: int) -> tuple[Trig, Trig]:
    """``(cos rτ, sin rτ)`` as Trig sums."""
    zero = ground.poly([])
    if r == 1:
        return (Trig(ground.poly([ground.scalar(0), ground.scalar(1)]), zero, ground),
                Trig(zero, ground.poly([ground.scalar(1)]), ground))
    one = ground.scalar(1)
    return Trig.from_fourier({r: one}, {}, ground), Trig.from_fourier({}, {r: one}, ground)


def _standard_form(setup: _Setup, ground: Ground, order: int) -> list[tuple[Trig, ...]]:
    """``F_k = (−g_k,1 sin r_1τ / r_1, g_k,1 cos r_1τ / r_1, …)`` for ``k = 1 … order``: per
    mode ``q = u cos rτ + v sin rτ``, ``q' = r(v cos rτ − u sin rτ)``, as Trig sums."""
    zero = ground.poly([])

    def const(value) -> Trig:
        return Trig(ground.poly([ground.scalar(value)]), zero, ground)

    harmonics = [_harmonic(ground, r) for r in setup.ratios]
    C, S = _harmonic(ground, 1)  # the drive's cos τ, sin τ
    bases = {}
    for i, (r, (Ci, Si)) in enumerate(zip(setup.ratios, harmonics, strict=True)):
        u, v = (ground.scalar(s) for s in setup.slow[2 * i: 2 * i + 2])
        bases[setup.qs[i]] = Ci * u + Si * v
        qp = Ci * v - Si * u
        bases[setup.qps[i]] = qp if r == 1 else qp * ground.scalar(r)
    cs, ss = sp.Symbol("_cos"), sp.Symbol("_sin")
    bases[cs], bases[ss] = C, S
    gens = (*setup.qs, *setup.qps, cs, ss)
    powers: dict[tuple[sp.Symbol, int], Trig] = {}

    def power(name: sp.Symbol, n: int) -> Trig:
        if n == 0:
            return const(1)
        if (name, n) not in powers:
            powers[name, n] = power(name, n - 1) * bases[name]
        return powers[name, n]

    out = []
    for k in range(1, order + 1):
        row: list[Trig] = []
        for i, (r, (Ci, Si)) in enumerate(zip(setup.ratios, harmonics, strict=True)):
            gk = Trig(zero, zero, ground)
            if k in setup.g and setup.g[k][i] != 0:
                poly = sp.Poly(setup.g[k][i], *gens)
                for exps, coeff in sorted(poly.as_dict().items()):
                    term = None
                    for name, n in zip(gens, exps, strict=True):
                        if n:
                            term = power(name, n) if term is None else term * power(name, n)
                    gk = gk + (const(1) if term is None else term) * ground.scalar(coeff)
            if r == 1:
                row += [gk * Si * ground.scalar(-1), gk * Ci]
            else:
                row += [gk * Si * ground.scalar(Fraction(-1, r)),
                        gk * Ci * ground.scalar(Fraction(1, r))]
        out.append(tuple(row))
    return out


def _mean(T: Trig):
    """The mean over τ of a Trig sum (its Fourier ``a_0``)."""
    cos, _ = T.to_fourier()
    return cos.get(0, T.ground.scalar(0))


def _constant(T: Trig) -> Trig:
    g = T.ground
    return Trig(g.poly([_mean(T)]), g.poly([]), g)


def _antiderivative(T: Trig) -> Trig:
    """The mean-free antiderivative in τ: ``a_n cos nτ → (a_n/n) sin nτ``,
    ``b_n sin nτ → −(b_n/n) cos nτ``."""
    g = T.ground
    cos, sin = T.to_fourier()
    return Trig.from_fourier({n: b * g.scalar(Fraction(-1, n)) for n, b in sin.items()},
                             {n: a * g.scalar(Fraction(1, n)) for n, a in cos.items() if n},
                             g)


def _partial(T: Trig, index: int) -> Trig:
    """``∂/∂x_index`` (``x = (u_1, v_1, …)``) of a Trig sum over ``QQ[u_1, v_1, …]`` (C is
    FLINT's gen 0)."""
    return Trig(MPoly(T.cos_part.p.derivative(index + 1)),
                MPoly(T.sin_part.p.derivative(index + 1)), T.ground)


def _multi_indices(dim: int, n: int):
    """Every ``α ∈ N^dim`` with ``|α| ≤ n``, the first index outermost."""
    if dim == 1:
        yield from ((a,) for a in range(n + 1))
        return
    for a in range(n + 1):
        for rest in _multi_indices(dim - 1, n - a):
            yield (a, *rest)


def _lowered(alpha: tuple[int, ...]) -> tuple[int, tuple[int, ...]] | None:
    """``(i, α − e_i)`` for the first nonzero index ``i`` of ``α`` (None: ``α = 0``)."""
    for i, e in enumerate(alpha):
        if e:
            return i, (*alpha[:i], e - 1, *alpha[i + 1:])
    return None


def _average(F: list[tuple[Trig, ...]], ground, order: int
             ) -> tuple[list[tuple[Trig, ...]], list[tuple[Trig, ...]]]:
    """``G_k`` and ``w_k`` (k = 1 … order) by the order-ε^k equations of the module docstring;
    ``F(y + W)`` by Taylor's formula in the slow variables ``(u_1, v_1, …)``."""
    dim = len(F[0])
    zero = Trig(ground.poly([]), ground.poly([]), ground)
    G: list[tuple[Trig, ...]] = []
    W: list[tuple[Trig, ...]] = []
    derivs: dict[tuple[int, tuple[int, ...]], tuple[Trig, ...]] = {}

    def d(m: int, alpha: tuple[int, ...]) -> tuple[Trig, ...]:  # ∂^α F_m / α!
        key = (m, alpha)
        if key not in derivs:
            lower = _lowered(alpha)
            if lower is None:
                derivs[key] = F[m - 1]
            else:
                i, prev = lower
                derivs[key] = tuple(_partial(c, i) * ground.scalar(Fraction(1, alpha[i]))
                                    for c in d(m, prev))
        return derivs[key]

    for k in range(1, order + 1):
        monomials: dict[tuple[int, ...], list[Trig]] = {}  # [Π W_i^α_i]_n, n < k
        rhs = [zero] * dim
        for m in range(1, k + 1):
            n = k - m  # the order still needed from the Taylor terms
            for alpha in _multi_indices(dim, n):  # W = O(ε): W^α starts at ε^|α|
                mono = _w_monomial(alpha, k, W, monomials, ground)[n]
                dm = d(m, alpha)
                rhs = [rhs[i] + dm[i] * mono for i in range(dim)]
        for i in range(1, k):
            Gj = G[k - i - 1]
            wi = W[i - 1]
            for comp in range(dim):
                acc = _partial(wi[comp], 0) * Gj[0]
                for x in range(1, dim):
                    acc = acc + _partial(wi[comp], x) * Gj[x]
                rhs[comp] = rhs[comp] - acc
        Gk = tuple(_constant(c) for c in rhs)
        G.append(Gk)
        if k < order:
            W.append(tuple(_antiderivative(c - gk) for c, gk in zip(rhs, Gk, strict=True)))
    return G, W


def _w_monomial(alpha: tuple[int, ...], k: int, W: list[tuple[Trig, ...]],
                monomials: dict[tuple[int, ...], list[Trig]], ground) -> list[Trig]:
    """``[Π W_i^α_i]_n`` for ``n < k`` from the known ``w_1 … w_(k−1)`` (cached)."""
    if alpha not in monomials:
        zero = Trig(ground.poly([]), ground.poly([]), ground)
        lower = _lowered(alpha)
        if lower is None:
            one = Trig(ground.poly([ground.scalar(1)]), ground.poly([]), ground)
            monomials[alpha] = [one] + [zero] * (k - 1)
        else:
            comp, prev = lower
            base = _w_monomial(prev, k, W, monomials, ground)
            out = []
            for n in range(k):
                acc = zero
                for j in range(1, min(n, len(W)) + 1):
                    acc = acc + W[j - 1][comp] * base[n - j]
                out.append(acc)
            monomials[alpha] = out
    return monomials[alpha]


def _polar(Gk: tuple[sp.Expr, sp.Expr]) -> tuple[sp.Expr, sp.Expr]:
    """``(R_k, Φ_k)`` from ``G_k = (U_k, V_k)``: ``u = r cos φ``, ``v = −r sin φ``,
    ``r' = (u U + v V)/r``, ``φ' = (v U − u V)/r²``, reduced by ``sin² φ = 1 − cos² φ``."""
    c, s = sp.Symbol("_c"), sp.Symbol("_s")
    Uk, Vk = (e.xreplace({U: R * c, V: -R * s}) for e in Gk)
    radial = sp.expand((R * c * Uk - R * s * Vk) / R)
    phase = sp.expand((-R * s * Uk - R * c * Vk) / R**2)
    out = []
    for e in (radial, phase):
        e = sp.reduced(e, [s**2 + c**2 - 1], s, c)[1] if e.has(s) else e
        out.append(sp.collect(sp.expand(e.xreplace({c: sp.cos(PHI), s: sp.sin(PHI)})), R))
    return out[0], out[1]


def _trig_expr(T: Trig, ground, tau: sp.Symbol) -> sp.Expr:
    """A Trig sum as ``Σ a_n cos nτ + b_n sin nτ`` (SymPy)."""
    cos, sin = T.to_fourier()
    return sp.Add(*(ground.to_sympy(a) * sp.cos(n * tau) for n, a in sorted(cos.items())),
                  *(ground.to_sympy(b) * sp.sin(n * tau) for n, b in sorted(sin.items())))


def _one_oscillator(flow: SlowFlow, what: str) -> None:
    """Refuse a system's flow where the one oscillator's ``(r, φ)`` is meant."""
    if flow.system is not None:
        raise InputError(f"system {flow.source!r}: {what} takes one oscillator's slow flow "
                         "(r, phi); a system's resonant modes have coupled_modes and "
                         "numerics.references.energy_exchange")


def fixed_points(flow: SlowFlow, eps: float, values: dict[str, float] | None = None,
                 guesses: tuple[tuple[float, float], ...] = ((1.0, 0.0),)
                 ) -> list[tuple[float, float]]:
    """Fixed points ``(r, φ)`` of a driven slow flow (the steady states), by Newton's method in
    van der Pol's variables from each guess; for an autonomous flow the positive roots ``r`` of
    ``dr/dt`` (the limit cycles) with ``φ`` the phase rate ``dφ/dt`` there."""
    _one_oscillator(flow, "fixed_points")
    subs = {sp.Symbol("eps"): eps, **{sp.Symbol(k): v for k, v in (values or {}).items()}}
    if not flow.driven:
        dr, dphi = (e.subs(subs) for e in flow.rates)
        out = []
        coeffs = [float(c) for c in sp.Poly(sp.expand(dr), R).all_coeffs()]
        dp = sp.lambdify(R, dphi, "math")
        for root in np.roots(coeffs):
            if abs(root.imag) < 1e-12 * (1 + abs(root)) and root.real > 0:
                out.append((float(root.real), float(dp(root.real))))
        return sorted(out)
    Gs = [sp.Add(*(sp.Symbol("eps") ** (k + 1) * Gk[i] for k, Gk in enumerate(flow.cartesian)))
          for i in range(2)]
    f = sp.lambdify((U, V), [e.subs(subs) for e in Gs], "numpy")
    J = sp.lambdify((U, V), sp.Matrix([[sp.diff(e.subs(subs), x) for x in (U, V)]
                                        for e in Gs]), "numpy")
    found = []
    for r0, p0 in guesses:
        x = np.array([r0 * np.cos(p0), -r0 * np.sin(p0)])
        # NOTE: Newton's method by hand, not numerics.newton.iterate: derive stands above
        # numerics in the package's stage list, and a stage imports only stages above it.
        for _ in range(100):
            step = np.linalg.solve(np.asarray(J(*x), dtype=float), np.asarray(f(*x), dtype=float))
            x = x - step
            if np.max(np.abs(step)) < 1e-15 * (1 + np.max(np.abs(x))):
                break
        else:
            continue
        found.append((float(np.hypot(*x)), float(np.arctan2(-x[1], x[0]))))
    return found


def transient(flow: SlowFlow, eps: float, q0: float, p0: float, times: np.ndarray,
              values: dict[str, float] | None = None, rtol: float = 1e-12) -> np.ndarray:
    """``q(t)`` and ``q̇(t)`` predicted by the slow flow from ``q(0) = q0``, ``q̇(0) = p0``: the
    averaged equations integrated (SciPy's DOP853) from ``y(0)`` that the near-identity
    transformation maps to the initial state, then mapped back, ``x = y + Σ ε^j w_j(y, τ)``.
    Shape ``(2, len(times))``.  Error ``O(ε^order)`` over ``t = O(1/ε)``."""
    from scipy.integrate import solve_ivp

    _one_oscillator(flow, "transient")
    eps_s, tau = sp.Symbol("eps"), sp.Symbol("tau")
    subs = {eps_s: eps, **{sp.Symbol(k): v for k, v in (values or {}).items()}}
    sigma = float(subs.get(SIGMA, 0.0)) if flow.driven else 0.0
    w = 1 + eps * sigma
    # the τ-time flow: the t-time G divided by ω (exact in floating point)
    Gs = [sp.Add(*(eps_s ** (k + 1) * Gk[i] for k, Gk in enumerate(flow.cartesian))).subs(subs)
          / w for i in range(2)]
    rhs = sp.lambdify((U, V), Gs, "numpy")
    Ws = [sp.Add(*(eps_s ** (j + 1) * Wj[i] for j, Wj in enumerate(flow.transform))).subs(subs)
          for i in range(2)]
    back = sp.lambdify((U, V, tau), Ws, "numpy")

    def to_x(y: np.ndarray, t: np.ndarray) -> np.ndarray:
        dw = np.asarray([np.broadcast_to(c, np.shape(t)) for c in back(y[0], y[1], t)])
        return y + dw

    x0 = np.array([q0, p0 / w])  # at τ = 0: q = u, dq/dτ = v
    y0 = x0.copy()
    for _ in range(60):  # y0 = x0 − W(y0, 0), a contraction for small ε
        y0 = x0 - (to_x(y0, np.float64(0.0)) - y0)
    taus = w * np.asarray(times, dtype=float)
    sol = solve_ivp(lambda _t, y: np.asarray(rhs(*y), dtype=float), (0.0, taus[-1]), y0,
                    method="DOP853", t_eval=taus, rtol=rtol, atol=rtol * 1e-2)
    x = to_x(sol.y, taus)
    q = x[0] * np.cos(taus) + x[1] * np.sin(taus)
    qp = -x[0] * np.sin(taus) + x[1] * np.cos(taus)
    return np.array([q, w * qp])


def simulate(osc: Oscillator, eps: float, q0: float, p0: float, times: np.ndarray,
             values: dict[str, float] | None = None, rtol: float = 1e-12) -> np.ndarray:
    """The equation itself (SciPy's DOP853 at ``rtol``): ``(q, q̇)`` at ``times`` from
    ``(q0, p0)``, the reference the slow flow's transients are measured against.  ``values``
    gives the symbolic parameters numbers (``w`` the drive's frequency, not σ)."""
    from scipy.integrate import solve_ivp

    eq = osc.equation
    q, qdot = eq.derivatives[:2]
    subs = {eq.small: eps, **{sp.Symbol(k): v for k, v in (values or {}).items()}}
    accel = sp.lambdify((eq.time, q, qdot), (osc.drive - osc.force).subs(subs), "math")
    sol = solve_ivp(lambda t, y: (y[1], accel(t, y[0], y[1])), (0.0, float(times[-1])),
                    (q0, p0), method="DOP853", t_eval=times, rtol=rtol, atol=rtol * 1e-2)
    return sol.y


@dataclass(frozen=True)
class CycleSeries:
    """A limit cycle as a fixed point of an autonomous slow flow: ``r* = Σ ε^j radius[j]``
    (the root of ``dr/dt``, to ``ε^(order−1)``) and its frequency ``ω = Σ ε^j omega[j]``
    (``1 + dφ/dt`` there, to ``ε^order``, exact: ω does not depend on the convention)."""

    radius: tuple[sp.Expr, ...]
    omega: tuple[sp.Expr, ...]
    slope: sp.Expr  # R_1'(r₀): the cycle attracts for ε·slope < 0


def cycle_series(flow: SlowFlow) -> list[CycleSeries]:
    """Every positive root ``r₀`` of ``R_1`` where ``R_1'(r₀) ≠ 0`` (rational roots; an
    irrational one is kept as SymPy's exact algebraic number), continued order by order:
    ``r_i`` from the ε^i part of ``(dr/dt)/ε``, linear in ``r_i`` with slope ``R_1'(r₀)``."""
    _one_oscillator(flow, "cycle_series")
    if flow.driven:
        raise InputError(f"{flow.name}: a driven flow's fixed points depend on the drive; "
                         "use fixed_points with values")
    eps = sp.Symbol("eps")
    N = flow.order

    def truncated(expr: sp.Expr, top: int) -> sp.Expr:
        expr = sp.expand(expr)
        return sp.Add(*(expr.coeff(eps, i) * eps**i for i in range(top + 1)))

    out = []
    R1 = flow.radial[0]
    if R1 == 0 or R1.free_symbols - {R}:
        return out
    for r0 in sp.Poly(R1, R).real_roots():
        slope = sp.diff(R1, R).subs(R, r0)
        if r0 <= 0 or slope == 0 or any(c.radius[0] == r0 for c in out):
            continue
        rstar = r0
        for i in range(1, N):
            radial = truncated(sum(eps**k * flow.radial[k].subs(R, rstar) for k in range(N)), i)
            rstar = rstar - sp.radsimp(radial.coeff(eps, i) / slope) * eps**i
        phase = truncated(sum(eps ** (k + 1) * flow.phase[k].subs(R, rstar) for k in range(N)),
                          N)
        out.append(CycleSeries(
            radius=tuple(sp.expand(rstar).coeff(eps, i) if i else r0 for i in range(N)),
            omega=(sp.Integer(1), *(sp.radsimp(phase.coeff(eps, k)) for k in range(1, N + 1))),
            slope=slope))
    return out
