"""The driver: derive -> lower -> render -> write, each stage called once, in order.

Every command that writes files comes through :func:`compile_target`: ``generate`` (a free
oscillator, ``driven``, ``balance``, ``fourier``), ``choose … --out`` and ``demo``.  A
:class:`methods.Target` says what its method derives and how it lowers; :mod:`emit` renders
the :class:`lower.Unit` and writes it.  Every target file is checked before the derivation
starts.
"""

from __future__ import annotations

import shlex
from functools import partial
from pathlib import Path

from .derive.models import Model, check_module_name, check_order, model_by_name
from .emit.render import check_writable, render, write_files
from .errors import InputError
from .methods.registry import Candidate, Method
from .methods.targets import (
    BALANCE,
    CHOSEN_PERIOD,
    FOURIER,
    FREE,
    LIMIT_CYCLE,
    MATHIEU,
    MU,
    MU_DAMPED,
    NNM,
    SLOW_FLOW,
    SSM,
    TONGUE,
    ChoiceRequest,
    CycleRequest,
    FreeRequest,
    HarmonicsRequest,
    MathieuRequest,
    NormalModeRequest,
    Progress,
    ReductionRequest,
    Request,
    SlowFlowRequest,
    Target,
    TongueRequest,
)


def compile_target(target: Target, request: Request, out: Path,
                   progress: Progress | None = None, *, overwrite_edited: bool = False,
                   flag: str = "--out") -> list[Path]:
    """Check the targets, derive, lower, render, write: the files written."""
    names = target.files(request)
    check_writable(out, list(names), flag, overwrite_edited)
    derived = target.derive(request, progress)
    unit = target.lower(derived, request)
    files = render(unit)
    if set(files) != set(names):
        raise RuntimeError(f"rendered {sorted(files)}, announced {sorted(names)}")
    return write_files(out, files, flag, overwrite_edited)


def generate(model: str | Model, order: int, out: Path, allow_divergent: bool = False,
             progress: Progress | None = None, *,
             overwrite_edited: bool = False, flag: str = "--out") -> list[Path]:
    """``lindstedt generate``: the numba module and the LaTeX of ``model`` at ``order``.

    ``model`` is a registry name or a :class:`Model` built for ``order + 2``: the series is
    derived two orders further so the module can estimate its truncation error (``progress``
    follows the derivation, as in :func:`lindstedt.derive`).
    """
    order = check_order(order)
    m = model_by_name(model, order + 2) if isinstance(model, str) else model
    source = m.name if not m.source else f'"{m.source}" --name {m.name}' + "".join(
        f" --param {k}={v}" for k, v in m.given)
    command = f"lindstedt generate {source} --order {order}" + (
        " --allow-divergent" if allow_divergent else "")
    return compile_target(FREE, FreeRequest(order, command, m, allow_divergent), out, progress,
                          overwrite_edited=overwrite_edited, flag=flag)


def generate_limit_cycle(model: object, order: int, out: Path, *, resum_order: int | None = None,
                         overwrite_edited: bool = False, flag: str = "--out") -> list[Path]:
    """``lindstedt generate`` of a self-excited oscillator: its limit cycle's evaluators, the
    partial sums to ``order`` and ω resummed from the exact series to ``resum_order``
    (default :data:`methods.RADIUS_ORDER`; at least ``order + 2``)."""
    order = check_order(order)
    if order < 1:
        raise InputError(f"order {order}: a limit cycle's evaluators start at order 1")
    if resum_order is not None and resum_order < order + 2:
        raise InputError(f"--resum-order {resum_order}: at least the order + 2 = {order + 2} "
                         "the evaluators' error estimate needs")
    command = f'lindstedt generate "{model.source}" --name {model.name} --order {order}' + (
        f" --resum-order {resum_order}" if resum_order is not None else "")
    return compile_target(LIMIT_CYCLE, CycleRequest(order, command, model, resum_order),
                          out, overwrite_edited=overwrite_edited, flag=flag)


def generate_driven(order: int, out: Path, *, damped: bool = False,
                    overwrite_edited: bool = False, flag: str = "--out") -> list[Path]:
    """``lindstedt generate driven``: A_n(ω) evaluators and the μ-expansion's derivation;
    ``damped``: A_n, B_n(ω, ε, f, Q) and the derivation with both secular conditions."""
    if damped:
        command = f"lindstedt generate driven --order {order} --damped"
        return compile_target(MU_DAMPED, Request(order, command), out,
                              overwrite_edited=overwrite_edited, flag=flag)
    return compile_target(MU, Request(order, f"lindstedt generate driven --order {order}"),
                          out, overwrite_edited=overwrite_edited, flag=flag)


def generate_balance(harmonics: int, out: Path, *, overwrite_edited: bool = False,
                     flag: str = "--out") -> list[Path]:
    """``lindstedt generate balance``: compiled harmonic-balance residual, Jacobian, Newton."""
    command = f"lindstedt generate balance --harmonics {harmonics}"
    return compile_target(BALANCE, HarmonicsRequest(harmonics, command), out,
                          overwrite_edited=overwrite_edited, flag=flag)


def generate_fourier(harmonics: int, out: Path, *, overwrite_edited: bool = False,
                     flag: str = "--out") -> list[Path]:
    """``lindstedt generate fourier``: the exact Fourier series of the free Duffing solution."""
    command = f"lindstedt generate fourier --harmonics {harmonics}"
    return compile_target(FOURIER, HarmonicsRequest(harmonics, command), out,
                          overwrite_edited=overwrite_edited, flag=flag)


def generate_choice(candidate: Candidate, command: str, out: Path,
                    verified: tuple[float, float], *, overwrite_edited: bool = False,
                    flag: str = "--out") -> list[Path]:
    """``lindstedt choose period … --out DIR``: just the chosen evaluator, NaN outside the
    range ``verified`` of x = εA² it was verified on."""
    request = ChoiceRequest(candidate.order, command, candidate.method.formula(candidate),
                            verified)
    return compile_target(CHOSEN_PERIOD, request, out, overwrite_edited=overwrite_edited,
                          flag=flag)


def generate_method(m: Method, order: int, out: Path, *, overwrite_edited: bool = False,
                    flag: str = "--out") -> list[Path]:
    """The module of a method ``choose … --out`` picked, as ``generate`` writes it."""
    if m.target is None:
        raise InputError(f"{m.name}: no emitted module")
    writer = {FREE: partial(generate, "duffing"), MU: generate_driven,
              MU_DAMPED: partial(generate_driven, damped=True),
              BALANCE: generate_balance, FOURIER: generate_fourier}[m.target]
    return writer(order, out, overwrite_edited=overwrite_edited, flag=flag)


def generate_slow_flow(osc: object, order: int, command: str, out: Path, *,
                       overwrite_edited: bool = False, flag: str = "--out") -> list[Path]:
    """``lindstedt slowflow … --out DIR``: the compiled slow-flow right sides of the
    :class:`models.Oscillator` ``osc`` to ``order`` and the LaTeX of the flow."""
    return compile_target(SLOW_FLOW, SlowFlowRequest(order, command, osc), out,
                          overwrite_edited=overwrite_edited, flag=flag)


def generate_mathieu(kind: str, m: int, order: int, out: Path, *,
                     overwrite_edited: bool = False, flag: str = "--out") -> list[Path]:
    """``lindstedt mathieu a|b --m M --order K --out DIR``: the resummed a_m(q) or b_m(q)."""
    from .derive.hill import mathieu_series

    mathieu_series(kind, m, 0)  # the kind and m checked before the derivation
    order = check_order(order)
    if order < 4:
        raise InputError(f"order {order}: a resummed Mathieu evaluator needs order ≥ 4")
    command = f"lindstedt mathieu {kind} --m {m} --order {order} --out DIR"
    return compile_target(MATHIEU, MathieuRequest(order, command, kind, m), out,
                          overwrite_edited=overwrite_edited, flag=flag)


def generate_nnm(system: object, mode: int, order: int, out: Path, *, amplitude: int = 0,
                 name: str = "system", command: str = "lindstedt generate SYSTEM",
                 progress: Progress | None = None, overwrite_edited: bool = False,
                 flag: str = "--out", allow_divergent: bool = False) -> list[Path]:
    """``lindstedt generate SYSTEM --mode M``: the mode's backbone and shape evaluators."""
    check_module_name(name)
    order = check_order(order)
    return compile_target(NNM, NormalModeRequest(order, command, system, mode, amplitude, name,
                                                 allow_divergent),
                          out, progress, overwrite_edited=overwrite_edited, flag=flag)


def generate_ssm(system: object, mode: int, order: int, out: Path, *, name: str,
                 command: str, outputs: tuple[int, ...] | None = None,
                 span: tuple[float, float] | None = None, overwrite_edited: bool = False,
                 flag: str = "--out") -> list[Path]:
    """``lindstedt generate SYSTEM --ssm M``: the reduced model's module and its LaTeX."""
    check_module_name(name)
    return compile_target(SSM, ReductionRequest(order, command, system, mode, outputs, span,
                                                name), out,
                          overwrite_edited=overwrite_edited, flag=flag)


TONGUE_MIN_ORDER = 12
# NOTE: nearest_singularity needs 12 coefficients for the radius that sets the verified range.


def generate_tongue(p: str, n: int, order: int, out: Path, *, overwrite_edited: bool = False,
                    flag: str = "--out") -> list[Path]:
    """``lindstedt tongues P --n N --order K --out DIR``: the resummed transition curves."""
    from .derive.hill import fourier_of_text, transition_curves

    transition_curves(fourier_of_text(p), n, 0)  # p and n checked before the derivation
    order = check_order(order)
    if order < TONGUE_MIN_ORDER:
        raise InputError(f"order {order}: resummed transition curves need order ≥ "
                         f"{TONGUE_MIN_ORDER}")
    command = f"lindstedt tongues {shlex.quote(p)} --n {n} --order {order} --out DIR"
    return compile_target(TONGUE, TongueRequest(order, command, p, n), out,
                          overwrite_edited=overwrite_edited, flag=flag)
