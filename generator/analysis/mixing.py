"""Combination tones of a multi-tone drive: ``q̈ + g(q, q̇) = Σ f_i cos ω_i t`` for any polynomial
``g`` with a linear stiffness and damping, by the perturbation series about the linear response
(two orders in the nonlinearity), checked against a simulated steady state.

Eq. 10.60's ``q̈ + q̇/Q + q + εq³`` is :func:`numerics.duffing_table`'s preset of it."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..limits import MAGNITUDES, MAX_DRIVES
from ..numerics.integrate import ForceTable, ToneFit, steady_state_fit
from .polynomial import driven_form


@dataclass(frozen=True)
class Tone:
    """A combination tone ``m₁ω₁ + m₂ω₂ (+ …)`` of the response, its predicted amplitude
    (through the second order of the nonlinearity) and the order at which it first appears."""

    combination: tuple[int, ...]
    frequency: float
    predicted: float
    order: int


def tone_label(combo: tuple[int, ...]) -> str:
    """``(2, -1)`` -> ``"2w1-w2"``, ``(-1, 2)`` -> ``"2w2-w1"`` (positive terms first)."""
    terms = sorted(((m, i) for i, m in enumerate(combo, 1) if m), key=lambda mi: mi[0] < 0)
    text = ""
    for m, i in terms:
        sign = "-" if m < 0 else ("+" if text else "")
        text += f"{sign}{'' if abs(m) == 1 else abs(m)}w{i}"
    return text or "0"


def _product(x: dict, y: dict) -> dict:
    """Product of phasor sums ``{combination: c}`` (``Σ c e^{i(m·ω)t}``)."""
    out: dict = {}
    for ka, a in x.items():
        for kb, b in y.items():
            k = tuple(i + j for i, j in zip(ka, kb, strict=True))
            out[k] = out.get(k, 0) + a * b
    return out


def _power(x: dict, n: int, one: dict) -> dict:
    out = one
    for _ in range(n):
        out = _product(out, x)
    return out


MIN_DRIVE_OMEGA = 2 * np.pi / 2000
# NOTE: numerics.steady_state_fit fits the tones over a 2000-unit window: a drive must
# complete a period in it (slower tones, which near-commensurate drives make, fit poorly).
MAX_PRODUCTS = 20_000_000
# NOTE: phasor products of the second order (|q₁| · |q₀|^(degree − 1) terms): a quintic force
# with four drives stays under it (~1 s); a degree-9 force with four drives does not.


MIXING_CONVERGED = 0.2
# NOTE: the expansion parameter ρ (the larger of ‖q₁‖/‖q₀‖ and ‖q₂‖/‖q₁‖, ‖·‖ the sum of the
# tones' amplitudes) must stay ≤ 0.2, so the first omitted order is ~ρ³ ≤ 1 % of q₀: the rule of
# the μ-expansion, whose last term must fall below 1 % of the first. At ρ ≈ 0.5
# (ε = 0.2, Q = 15, drives 0.4@0.8 and 0.3@1.9) q₀ + q₁ + q₂ put the ω₁ tone 61 % off the
# simulated one, worse than q₀ alone.


@dataclass(frozen=True)
class MixingSeries:
    """The combination tones to second order and the verdict on the expansion."""

    tones: tuple[Tone, ...]
    mean: float  # the response's constant part (an even force's offset; 0 for an odd one)
    expansion_parameter: float  # ρ = max(‖q₁‖/‖q₀‖, ‖q₂‖/‖q₁‖)
    converged: bool  # ρ ≤ MIXING_CONVERGED
    reason: str


def check_drives(drives: list[tuple[float, float]]) -> None:
    """At least one drive, at most :data:`MAX_DRIVES`, each amplitude and frequency finite,
    the amplitude within :data:`driven.MAGNITUDES` and the frequency ≥ MIN_DRIVE_OMEGA."""
    if not drives:
        raise InputError("mixing: give at least one drive F@W")
    if len(drives) > MAX_DRIVES:
        raise InputError(f"drives: {len(drives)} given, at most {MAX_DRIVES} (the tones to second "
                         "order grow like (2k)^5: 5 drives make 591 tones and 12 s of fitting, "
                         "6 make 1334 and a minute)")
    for f, w in drives:
        if not (math.isfinite(f) and math.isfinite(w)):
            raise InputError(f"drive {f!r}@{w!r}: not finite")
        if not MAGNITUDES[0] <= abs(f) <= MAGNITUDES[1]:
            raise InputError(f"drive {f!r}@{w!r}: the amplitude must be nonzero, within "
                             f"{MAGNITUDES[0]:g}..{MAGNITUDES[1]:g}")
        if w < MIN_DRIVE_OMEGA:
            raise InputError(f"drive {f!r}@{w!r}: frequency below {MIN_DRIVE_OMEGA:.2g}, where "
                             "the simulation's 2000-unit window holds less than one period")


def mixing_series(table: ForceTable, drives: list[tuple[float, float]]) -> MixingSeries:
    """Combination tones of ``q̈ + kq + γq̇ + N(q, q̇) = Σ f_i cos ω_i t`` (``table`` holds the
    whole force; ``k, γ > 0``) to the second order in the nonlinearity ``N``, with the
    expansion parameter ρ and whether the series converges (:data:`MIXING_CONVERGED`).

    ``q₀ = Σ Re(χ(ω_i) f_i e^{iω_i t})``, ``χ(ν) = 1/(k − ν² + iγν)``; ``q₁ = −χ·[N(q₀)]``,
    ``q₂ = −χ·[∂N/∂q (q₀) q₁ + ∂N/∂q̇ (q₀) q̇₁]``, each a sum over combinations of the drive
    frequencies (phasor products).  For eq. 10.60's ``εq³`` and two drives, ``q₁`` holds ω₁, ω₂,
    3ω₁, 3ω₂, 2ω₁ ± ω₂, 2ω₂ ± ω₁ — not ω₁ ± ω₂, which a cubic force cannot make (a quadratic one
    does); ``q₂ = −3εχ·[q₀²q₁]`` the five-fold ones."""
    check_drives(drives)
    terms = table.terms
    k, gamma = terms.get((1, 0), 0.0), terms.get((0, 1), 0.0)
    if not k > 0:
        raise InputError(f"the linear stiffness {k:g} must be > 0: the mixing series expands "
                         "about the linear response of a stable equilibrium")
    if not gamma > 0:
        raise InputError("no damping (Q inf): mixing needs a linear damping term (such as "
                         "q'/Q, finite Q) for a steady state" if gamma == 0 else
                         f"the linear damping {gamma:g} < 0: no steady state")
    nonlinear = [(a, b, c) for (a, b), c in sorted(terms.items()) if a + b >= 2]
    n = len(drives)
    omegas = np.array([w for _, w in drives])
    zero = (0,) * n

    def chi(combo: tuple[int, ...]) -> complex:
        nu = float(np.dot(combo, omegas))
        return 1 / (k - nu * nu + 1j * gamma * nu)

    def velocity(x: dict) -> dict:
        return {c: 1j * float(np.dot(c, omegas)) * v for c, v in x.items()}

    def add(out: dict, x: dict, scale: complex) -> None:
        for c, v in x.items():
            out[c] = out.get(c, 0) + scale * v

    one = {zero: 1.0}
    q0: dict = {}
    with np.errstate(over="ignore", invalid="ignore"):
        for i, (f, _) in enumerate(drives):
            e = tuple(int(j == i) for j in range(n))
            q0[e] = chi(e) * f / 2
            q0[tuple(-m for m in e)] = np.conj(q0[e])
        v0 = velocity(q0)
        n0: dict = {}
        for a, b, c in nonlinear:
            add(n0, _product(_power(q0, a, one), _power(v0, b, one)), c)
        q1 = {cb: -chi(cb) * v for cb, v in n0.items()}
        degree = max((a + b for a, b, _ in nonlinear), default=1)
        if len(q1) * len(q0) ** max(degree - 1, 0) > MAX_PRODUCTS:
            raise InputError(f"{len(drives)} drives and a force of degree {degree}: the second "
                             f"order takes more than {MAX_PRODUCTS:.0e} phasor products; drop "
                             "a drive or the highest power")
        v1 = velocity(q1)
        n1: dict = {}
        for a, b, c in nonlinear:
            if a:
                add(n1, _product(_product(_power(q0, a - 1, one), _power(v0, b, one)), q1),
                    a * c)
            if b:
                add(n1, _product(_product(_power(q0, a, one), _power(v0, b - 1, one)), v1),
                    b * c)
        q2 = {cb: -chi(cb) * v for cb, v in n1.items()}
    if not all(np.isfinite(v) for part in (q0, q1, q2) for v in part.values()):
        size = max(abs(v) for v in q0.values())
        raise InputError(f"drives {' '.join(f'{f:g}@{w:g}' for f, w in drives)}: the linear "
                         f"response {2 * size:.3g} makes the second-order tones overflow; the "
                         "expansion needs the nonlinear force small beside the linear one")
    mean = float(sum(part.get(zero, 0) for part in (q0, q1, q2)).real)
    tones: dict = {}
    for order, part in ((0, q0), (1, q1), (2, q2)):
        for c, v in part.items():
            nu = float(np.dot(c, omegas))
            if nu <= 1e-12:
                continue
            # combinations at the same frequency add; label by the lowest order's combination
            key = round(nu, 12)
            prev = tones.get(key)
            tones[key] = (prev[0] if prev else c, (prev[1] if prev else 0) + v,
                          min(order, prev[2]) if prev else order)
    norms = [sum(abs(v) for v in part.values()) for part in (q0, q1, q2)]
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = float(max(norms[1] / norms[0], norms[2] / norms[1] if norms[1] > 0 else 0.0))
    converged = rho <= MIXING_CONVERGED
    reason = (f"expansion parameter {rho:.3g} ≤ {MIXING_CONVERGED}: the first omitted order is "
              f"~{rho**3:.1e} of q0" if converged else
              f"expansion parameter {rho:.3g} > {MIXING_CONVERGED} (the nonlinear force is not "
              "small beside the linear one): q0 + q1 + q2 is not converging, the predicted "
              "tones can be off by tens of percent; trust the simulated ones")
    ordered = sorted((Tone(c, nu, float(2 * abs(v)), order)
                      for nu, (c, v, order) in tones.items()),
                     key=lambda tone: (tone.order, tone.frequency))
    return MixingSeries(tuple(ordered), mean, rho, converged, reason)


def simulated_fit(table: ForceTable, drives: list[tuple[float, float]],
                  tones: list[Tone]) -> ToneFit:
    """The simulated steady state's amplitude at each tone (from rest, after the transients)
    and its standard error (:func:`numerics.steady_state_fit`), or :class:`InputError` when
    the simulated orbit overflows: no steady state to compare."""
    fit = steady_state_fit(table, [f for f, _ in drives], [w for _, w in drives],
                           [t.frequency for t in tones])
    if np.any(np.isnan(fit.amplitudes)):
        given = " ".join(f"{f:g}@{w:g}" for f, w in drives)
        why = ("RK4 at 64 steps a period is unstable there: a stiff damping or a large "
               "nonlinear force")
        cubic = table.terms.get((3, 0), 0.0)
        if cubic < 0:
            why = (f"a softening spring (q^3 coefficient {cubic:g}) driven over its barrier "
                   f"at |q| = {1 / np.sqrt(-cubic):.3g} escapes to infinity, or {why}")
        raise InputError(f"drives {given}: the simulated orbit overflows ({why}); there is no "
                         "steady state to compare the tones with")
    return fit


MIXING_ANSATZ = "the mixing series (q'' + g(q, q') = sum f_i cos(w_i t), g polynomial)"


def mixing_equation(text: str, values: dict[str, str], name: str = "oscillator"
                    ) -> tuple[ForceTable, list[tuple[float, float]], tuple]:
    """``(table, drives, values)`` of :func:`mixing_series` for ``text``
    (:func:`driven.driven_form`, every drive frequency a number), the drives by ascending
    frequency."""
    form = driven_form(text, values, name, "mixing", MIXING_ANSATZ, False)
    drives = sorted(((f, float(c)) for f, c, _ in form.drives), key=lambda d: (d[1], d[0]))
    return ForceTable.of(form.floats()), drives, form.values


@dataclass(frozen=True, eq=False)
class Mixing:
    """What ``lindstedt mixing`` computes, once: the force ``table`` and its ``drives``, the
    predicted tones (:class:`MixingSeries`) and the simulated steady state's fit at them
    (:class:`numerics.integrate.ToneFit`); ``values`` the parameters given to a user's
    equation."""

    table: ForceTable
    drives: tuple[tuple[float, float], ...]
    series: MixingSeries
    fit: ToneFit
    values: tuple = ()


def mixing(table: ForceTable, drives: list[tuple[float, float]], values: tuple = ()) -> Mixing:
    """The tones of ``q̈ + g = Σ f_i cos ω_i t`` predicted and simulated: :class:`Mixing`."""
    series = mixing_series(table, drives)
    return Mixing(table, tuple(drives), series,
                  simulated_fit(table, drives, list(series.tones)), values)


def duffing_mixing(eps: float, Q: float, drives: list[tuple[float, float]]) -> Mixing:
    """:class:`Mixing` of the notes' ``q̈ + q̇/Q + q + εq³``, ε and Q checked first, then
    every drive's numbers (as :class:`driven.Drive` checks them)."""
    from ..numerics.integrate import duffing_table
    from .driven import Drive

    Drive(eps, 1.0, 1.0, Q)
    for f, w in drives:
        try:
            Drive(eps, f, w, Q)
        except InputError as exc:
            raise InputError(f"drive {f!r}@{w!r}: {exc}") from None
    return mixing(duffing_table(eps, 1 / Q), drives)


def equation_mixing(text: str, values: dict[str, str], name: str = "oscillator") -> Mixing:
    """:class:`Mixing` of a user's equation (:func:`mixing_equation`)."""
    table, drives, given = mixing_equation(text, values, name)
    return mixing(table, drives, given)
