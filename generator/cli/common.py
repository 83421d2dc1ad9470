"""What every command shares: the light constants (restated so that parsing needs no
SymPy), the progress bar, argument types and flags, the one-line parser, the report shape."""

from __future__ import annotations

import argparse
import json
import math
import numbers
import os
import re
import sys
import time
from collections.abc import Sequence
from fractions import Fraction
from pathlib import Path

from ..errors import InputError, clipped
from ..limits import COST_LIMIT_SECONDS, MAX_HARMONICS

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.


os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# NOTE: before NumPy is imported: the continuation's and the fits' matrices (≤ 200 × 200) run
# twice as fast on one BLAS thread as on OpenBLAS's pool on a busy machine (`response
# --harmonics 40`: 8.7 s against 17.3 s), and the cost estimates assume one thread.

FREE_MODELS = ("duffing", "pendulum", "helmholtz_duffing", "quintic", "cubic_quintic",
               "velocity_squared", "sinh_spring", "van_der_pol", "rayleigh")
# NOTE: models.MODELS, restated so that parsing arguments needs no SymPy (a test keeps them equal).
EMITTED = ("driven", "balance", "fourier")
# NOTE: generate's names for the driven oscillator's modules (not free oscillators).
SCENE_NAMES = ("clock", "hard-spring", "notes-driven")
# NOTE: choose.SCENES's keys, likewise.
DRIVEN_QUANTITIES = ("amplitudes", "response")
# NOTE: choose.DRIVEN_QUANTITIES, likewise.
SWEEP_KINDS = ("response", "stability", "subharmonic", "validity")
# NOTE: sweep.KINDS's keys, likewise.
DEFAULT_ORDER = 4
# NOTE: one default for every --order: it works for every command (`generate driven` at order 4
# takes ~13 s, at 6 about 4 min) and keeps T(A) within 1e-4 for |εA²| ≤ 0.3; ask for more.
DEFAULT_HARMONICS = 8
# NOTE: one default for every --harmonics: 8 odd harmonics put the response's folds on the true
# orbit's to 12 digits at the notes' parameters (`generate balance` compiles them in ~20 s).
PROGRESS_AFTER_SECONDS = 2.0
# NOTE: work shorter than this shows no progress bar (it would only flicker).


class ProgressBar:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal and the output is
    not JSON, and only once the work has taken ``PROGRESS_AFTER_SECONDS``; call it as
    ``progress(done, total)``, then ``progress.close()``."""

    def __init__(self, label: str, enabled: bool = True) -> None:
        self.label = label
        self.enabled = enabled and sys.stderr.isatty()
        self.start = time.monotonic()
        self.drawn = False

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or time.monotonic() - self.start < PROGRESS_AFTER_SECONDS:
            return
        width = 30
        filled = width * done // max(total, 1)
        sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] "
                         f"{done}/{total}")
        sys.stderr.flush()
        self.drawn = True

    def close(self) -> None:
        """Erase the bar's line, if one was drawn."""
        if self.drawn:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


def _rational(c: object) -> str:
    """Exact ``"p/q"`` (always with a denominator, so scripts can split on '/'); FLINT's
    ``fmpq`` prints its digits itself, however long."""
    return f"{c.p}/{c.q}"


def _params(pairs: Sequence[str] | None) -> dict[str, str]:
    """``--param NAME=VALUE`` pairs, each name once."""
    values: dict[str, str] = {}
    for pair in pairs or ():
        name, sep, value = pair.partition("=")
        name = name.strip()
        if not sep or not name or not value.strip():
            raise InputError(f"--param {pair!r}: write NAME=VALUE, e.g. alpha=1/3")
        if name in values:
            raise InputError(f"--param {name}: given twice")
        values[name] = value.strip()
    return values


def _fraction_text(c: object) -> str:
    """``"p/q"`` of a Fraction; an algebraic number (a limit cycle in Q(a₀)) as SymPy's str,
    exact (``"-3*2**(3/4)/2560"``)."""
    if getattr(c, "is_Rational", False):  # SymPy's Rational (no import: start-up)
        c = Fraction(int(c.p), int(c.q))
    elif not isinstance(c, Fraction):
        return str(c)
    return f"{_int_text(c.numerator)}/{_int_text(c.denominator)}"


INT_TEXT_BITS = 14_000
# NOTE: below 4300 digits, Python's own str(); beyond it Python refuses (a guard against slow
# parsing of untrusted text), and van der Pol's coefficients pass it near order 150.


def _int_text(n: int) -> str:
    """The decimal digits of an exact integer, however long (FLINT's conversion beyond
    :data:`INT_TEXT_BITS`)."""
    if n.bit_length() < INT_TEXT_BITS:
        return str(n)
    from flint import fmpz

    return str(fmpz(n))


def sp_text(expr) -> str:
    """A SymPy expression as text, terms in lexicographic order (``sympy.sstr``)."""
    import sympy as sp

    return sp.sstr(expr, order="lex")


def _out_folder(text: str, flag: str = "--out") -> Path:
    if not text.strip():
        raise InputError(f"{flag} {text!r}: empty; name a folder")
    return Path(text)


def _keyed(values: dict) -> dict:
    return {str(n): float(v) for n, v in sorted(values.items())}


def _first_harmonic(A: dict, B: dict) -> float:
    """r = √(A₁² + B₁²), the amplitude of the first harmonic whatever its phase."""
    return float(math.hypot(A.get(1, 0.0), B.get(1, 0.0)))


def _report(args: argparse.Namespace, compute, json_of, draw, table) -> int:
    """The shape of every effect command: check the plot path first (nothing is computed for
    a figure that cannot be written), compute the record once, then its printers: the figure
    (``draw(record, path)``), JSON or the table (of ``json_of(record)``).  matplotlib is
    imported only for --plot (a refused input answers without it)."""
    plot = _charts().check_plot_path(Path(args.plot)) if args.plot else None
    record = compute()
    data = json_of(record)
    if plot is not None:
        draw(record, plot)
    print(json.dumps(data) if args.json else "\n".join(table(data)))
    return 0


def _charts():
    from .. import charts

    return charts


CSV_HEADER = re.compile(r"[^,\[\]]+ \[[^,\[\]]*\](,[^,\[\]]+ \[[^,\[\]]*\])*")
# NOTE: every CSV this tool writes names its columns `name [meaning or unit]`: a file whose
# first line has that shape is one of its own, and only such a file is ever replaced.


def _csv_state(path: Path) -> str:
    """``"generated"`` for a CSV this tool wrote (:data:`CSV_HEADER`), else ``"foreign"``."""
    with path.open("rb") as fh:
        first = fh.readline(1 << 16).decode("utf-8", errors="replace").rstrip("\r\n")
    return "generated" if CSV_HEADER.fullmatch(first) else "foreign"


def check_csv_path(text: str) -> Path:
    """``--csv FILE`` before any work: a usable folder, and a file that is new or a CSV this
    tool wrote; else :class:`InputError` (one line, nothing computed or written)."""
    from ..emit.render import check_output_file

    path = Path(text)
    if not text.strip() or not path.name:
        raise InputError(f"--csv {text!r}: name a file")
    return check_output_file(path, "--csv", _csv_state)


def check_outputs(args: argparse.Namespace) -> tuple[Path | None, Path | None]:
    """``--plot`` and ``--csv`` checked before any work (matplotlib imported only for
    --plot): their paths, or None."""
    plot = _charts().check_plot_path(Path(args.plot)) if getattr(args, "plot", None) else None
    return plot, check_csv_path(args.csv) if getattr(args, "csv", None) else None


def _cell(x: object) -> str:
    """A CSV cell: an integer as itself, a float as its ``repr`` (shortest round-trip text:
    read back bit for bit), a boolean as 1 or 0.

    >>> _cell(0.1), _cell(3), _cell(True), _cell(float("nan"))
    ('0.1', '3', '1', 'nan')
    """
    if isinstance(x, numbers.Integral):  # bool too
        return str(int(x))
    return repr(float(x))


def write_csv(path: Path, columns: Sequence[tuple[str, str]], rows) -> Path:
    """Write ``rows`` under the header ``columns`` (``(name, meaning)`` pairs: ``name
    [meaning]``) into ``path`` atomically (a temporary in its folder, then a rename: nothing
    half-written on any failure)."""
    from ..emit.render import write_files

    header = ",".join(f"{name} [{meaning}]" for name, meaning in columns)
    if not CSV_HEADER.fullmatch(header):
        raise ValueError(f"write_csv: {header!r}: a column's name or meaning holds ',', '[' "
                         "or ']'")
    lines = [header, *(",".join(_cell(x) for x in row) for row in rows)]
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    write_files(folder, {path.name: ("\n".join(lines) + "\n").encode()}, "--csv",
                ours=_csv_state)
    return path


def _equation_args(args: argparse.Namespace, flags: Sequence[str],
                   required: Sequence[str]) -> bool:
    """Whether an EQUATION was given; refuses in one line the flags it replaces beside it, its
    own flags without it, and a missing required flag without it."""
    if args.model is not None:
        given = [f"--{k}" for k in flags if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)}: with an equation give its parameters with "
                             "--param (e.g. --param eps=1/10) and the drive in the equation")
        return True
    if args.param or args.name:
        raise InputError("--param/--name: give an equation (EQUATION) to take them")
    missing = [f"--{k}" for k in required if getattr(args, k) is None]
    if missing:
        raise InputError(f"the following arguments are required: {', '.join(missing)}")
    return False


def interval(lo: float, hi: float, digits: int = 4) -> str:
    """``[lo, hi]`` to ``digits`` significant digits, or as many more as tell two different
    ends apart (a range the user gave must not print as ``[1, 1]``).

    >>> interval(1, 1.0000001)
    '[1, 1.0000001]'
    >>> interval(0.5, 2.25)
    '[0.5, 2.25]'
    """
    for d in range(digits, 18):
        a, b = f"{lo:.{d}g}", f"{hi:.{d}g}"
        if a != b or lo == hi:
            return f"[{a}, {b}]"
    return f"[{lo!r}, {hi!r}]"


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not an integer") from None


def _order(text: str) -> int:
    """An order K (or an index such as mathieu's m): a non-negative integer."""
    value = _integer(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value}: must be ≥ 0")
    return value


def _positive(text: str) -> int:
    """A positive integer (workers, points per task, a mode's number, slowflow's order)."""
    value = _integer(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value}: must be > 0")
    return value


def _count(text: str) -> int:
    """A number of harmonics: an integer in 1..MAX_HARMONICS."""
    value = _integer(text)
    if not 1 <= value <= MAX_HARMONICS:
        raise argparse.ArgumentTypeError(f"{value}: must be in 1..{MAX_HARMONICS}")
    return value


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not a number") from None


def _real(text: str) -> float:
    """A finite real number (scientific notation and a leading minus welcome)."""
    value = _number(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r}: not finite")
    return value


def _nonnegative(text: str) -> float:
    """A finite real number ≥ 0 (a damping ratio)."""
    value = _real(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be ≥ 0")
    return value


def _positive_real(text: str) -> float:
    """A finite real number > 0 (a tolerance)."""
    value = _real(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be > 0")
    return value


def _quality(text: str) -> float:
    """A quality factor Q > 0; ``inf`` means undamped."""
    if not _number(text) > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be > 0 (inf: undamped)")
    return float(text)


class _Parser(argparse.ArgumentParser):
    """argparse with the project's one-line errors (no usage dump), exit status 2, and any token
    that starts like a number (``-1e-8``, ``-.5``, ``-0.3@1.3``) taken as a value, not a flag."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str) -> None:  # type: ignore[override]
        # one prefix for every error, a subcommand's argparse ones included
        message = clipped(self._did_you_mean(message))
        self.exit(2, f"lindstedt: error: {self.prog.removeprefix('lindstedt ')}: {message}\n"
                  if self.prog != "lindstedt" else f"lindstedt: error: {message}\n")

    def _did_you_mean(self, message: str) -> str:
        """``message`` with ``did you mean …?`` for a misspelled command or flag: the closest
        spellings (``difflib``) among the commands, or among the flags of every command."""
        import difflib

        choice = re.match(r"argument (\S+): invalid choice: '([^']*)' \(choose from (.*)\)$",
                          message)
        if choice:
            names = re.findall(r"'([^']*)'", choice.group(3))
            close = difflib.get_close_matches(choice.group(2), names, n=1)
            if not close:
                return message
            return (f"argument {choice.group(1)}: invalid choice: {choice.group(2)!r}; did you "
                    f"mean {close[0]!r}? (choose from {choice.group(3)})")
        if message.startswith("unrecognized arguments:"):
            flags = {f for parser in self._parsers() for action in parser._actions
                     for f in action.option_strings if f.startswith("--")}
            hints = []
            for token in message.split(":", 1)[1].split():
                name = token.split("=", 1)[0]
                if name.startswith("--") and name not in flags:
                    close = difflib.get_close_matches(name, sorted(flags), n=1)
                    if close:
                        hints.append(f"{close[0]} for {name}")
            return message + (f"; did you mean {', '.join(hints)}?" if hints else "")
        return message

    def _parsers(self) -> list[argparse.ArgumentParser]:
        """This parser and every subcommand's."""
        out: list[argparse.ArgumentParser] = [self]
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                out += list(action.choices.values())
        return out


DEPRECATED_IN = "the next release"
# NOTE: an old spelling keeps working for one release, with a one-line note on stderr.


class _Deprecated(argparse.Action):
    """An old spelling of a flag, kept for one release: a one-line note on stderr naming the
    new spelling (``new``), then the value stored where the new flag stores it (``dest``);
    with ``nargs=0``, ``const``.  Hidden from ``--help``."""

    def __init__(self, option_strings: Sequence[str], dest: str, new: str, **kwargs) -> None:
        self.new = new
        kwargs.setdefault("help", argparse.SUPPRESS)
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        print(f"lindstedt: note: {option_string} is deprecated and goes in {DEPRECATED_IN}; "
              f"use {self.new}", file=sys.stderr)
        setattr(namespace, self.dest, self.const if self.nargs == 0 else values)


def _deprecated(p: argparse.ArgumentParser, old: str, new: str, dest: str, **kwargs) -> None:
    """Add ``old``, the deprecated spelling of ``new`` (which stores into ``dest``)."""
    p.add_argument(old, action=_Deprecated, new=new, dest=dest, **kwargs)


SPAN_FORMS = {1: "W", 2: "A:B", 3: "A:B:N"}
# NOTE: the one syntax of a frequency (or any abscissa) on every command: one value W, a range
# A:B, or a grid A:B:N (N points); each command accepts the forms that mean something to it.


class _Span(argparse.Action):
    """``W``, ``A:B`` or ``A:B:N`` (the forms in ``forms``): W into ``into[0]``, A and B into
    ``into[1]`` and ``into[2]``, N into ``into[3]``."""

    def __init__(self, option_strings: Sequence[str], dest: str, forms: Sequence[str],
                 into: Sequence[str | None], **kwargs) -> None:
        self.forms, self.into = tuple(forms), tuple(into)
        super().__init__(option_strings, dest, metavar="|".join(self.forms), **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        parts = str(values).split(":")
        if SPAN_FORMS.get(len(parts)) not in self.forms:
            raise argparse.ArgumentError(self, f"{values!r}: write {' or '.join(self.forms)}")
        try:
            numbers = [_real(part) for part in parts[:2]] + [_positive(part)
                                                            for part in parts[2:]]
        except argparse.ArgumentTypeError as exc:  # its text names the bad part
            raise argparse.ArgumentError(self, str(exc) if len(parts) == 1 else
                                         f"{values!r}: {exc}") from None
        names = self.into[:1] if len(numbers) == 1 else self.into[1:1 + len(numbers)]
        for name, number in zip(names, numbers, strict=True):
            setattr(namespace, name, number)


def _flag_span(p: argparse.ArgumentParser, flag: str, forms: Sequence[str], meaning: str,
               into: Sequence[str | None], points: int | None = None,
               required: bool = False) -> None:
    """``flag`` in the forms ``forms`` (:data:`SPAN_FORMS`), stored into ``into`` (see
    :class:`_Span`); ``points``: N's default."""
    p.add_argument(flag, action=_Span, forms=forms, into=into, required=required, help=meaning)
    p.set_defaults(**{name: None for name in into if name is not None})
    if points is not None:
        p.set_defaults(**{into[3]: points})


def _flag_omega(p: argparse.ArgumentParser, forms: Sequence[str], meaning: str,
                points: int | None = None, required: bool = False) -> None:
    """--omega in the command's forms: W into ``omega``, A:B into ``omega_min``/``omega_max``,
    N into ``points`` (default ``points``)."""
    _flag_span(p, "--omega", forms, meaning, ("omega", "omega_min", "omega_max", "points"),
               points, required)


def _flag_range_bounds(p: argparse.ArgumentParser, low: str, high: str) -> None:
    """The deprecated single bounds ``low`` and ``high`` of ``--omega A:B``."""
    _deprecated(p, low, "--omega A:B", "omega_min", type=_real)
    _deprecated(p, high, "--omega A:B", "omega_max", type=_real)


def _flag_out(p: argparse.ArgumentParser, what: str, default: str | None = None,
              old: str | None = None) -> None:
    """--out DIR, the one output-folder flag (``old``: its deprecated spelling here)."""
    p.add_argument("--out", default=default, metavar="DIR", help=what)
    if old is not None:
        _deprecated(p, old, "--out", "out")


# One definition per flag: the same name means the same thing, with one help text and one
# default, in every command.

def _flag_oscillator(p: argparse.ArgumentParser, emitted: bool = False,
                     optional: bool = False) -> None:
    """The oscillator: a name of `lindstedt models` or an equation, with --param and --name
    (``optional``: the command says itself what it needs without one)."""
    extra = ("; or driven: μ-expansion A_n(ω), balance: harmonic-balance Newton solver, "
             "fourier: exact Fourier series of Duffing") if emitted else ""
    p.add_argument("model", metavar="EQUATION|NAME", **(dict(nargs="?", default=None)
                                                          if optional else {}),
                   help="an equation such as \"q'' + q + eps*(alpha*q**2 + q**3) = 0\" (q' and "
                   "q'' are the derivatives, eps the small parameter, other names parameters) "
                   f"or a name: {', '.join(FREE_MODELS)}{extra}")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="give a parameter an exact value, e.g. alpha=1/3 (repeatable; "
                   "default: parameters stay symbolic)")
    p.add_argument("--name", metavar="NAME",
                   help="the oscillator's name in output and file names (default: oscillator)")


def _flag_equation(p: argparse.ArgumentParser, example: str,
                   default: str = "the Duffing oscillator with the flags",
                   which: str = "every parameter needs one") -> None:
    """An optional EQUATION of the command's own form, with --param and --name."""
    p.add_argument("model", metavar="EQUATION", nargs="?", default=None,
                   help=f"an equation such as {example}; default: {default}")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="with EQUATION: an exact value for each of its parameters, e.g. "
                   f"eps=1/10 (repeatable; {which})")
    p.add_argument("--name", metavar="NAME",
                   help="with EQUATION: the oscillator's name in messages (default: oscillator)")


def _flag_order(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--order", type=_order, default=DEFAULT_ORDER, metavar="K",
                   help=f"{what}, an integer ≥ 0 (default {DEFAULT_ORDER})")


def _flag_harmonics(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--harmonics", type=_count, default=DEFAULT_HARMONICS, metavar="N",
                   help=f"{what}, an integer in 1..{MAX_HARMONICS} (default {DEFAULT_HARMONICS})")


def _flag_allow_slow(p: argparse.ArgumentParser, deprecated_force: bool = True) -> None:
    """--allow-slow (and in series/generate its old spelling --force, which elsewhere is the
    drive amplitude)."""
    p.add_argument("--allow-slow", action="store_true",
                   help=f"run even when the estimate exceeds {COST_LIMIT_SECONDS:.0f} s "
                   "(default: refuse)")
    if deprecated_force:
        _deprecated(p, "--force", "--allow-slow (--force F is the drive amplitude f)",
                    "allow_slow", nargs=0, const=True)


def _flag_overwrite_edited(p: argparse.ArgumentParser) -> None:
    p.add_argument("--overwrite-edited", action="store_true",
                   help="replace generated files even when they were edited by hand since "
                   "(default: refuse, so an edit is never lost silently)")


def _flag_json(p: argparse.ArgumentParser, what: str = "the JSON contract") -> None:
    p.add_argument("--json", action="store_true",
                   help=f"print {what} on stdout instead of the table (no progress bar)")


def _flag_plot(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the figure into FILE (.png, .svg or .pdf; default: none)")


def _flag_csv(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--csv", metavar="FILE",
                   help=f"also write {what} into FILE as CSV: a header row naming each column "
                   "`name [meaning]`, one row per point, floats as Python's repr (written "
                   "whole or not at all; replaces only a CSV lindstedt wrote)")


def _flag_drive(p: argparse.ArgumentParser, required: bool, omega: str | None,
                Q: str | None = "optional", force: bool = True, notes: bool = False,
                omega_forms: Sequence[str] = ("W",)) -> None:
    """--eps, --force, --omega, --Q of q'' + q'/Q + q + eps q^3 = f cos(w t) (``omega``: its
    meaning, None for none, in the forms ``omega_forms``; ``Q``: "optional", "required" or
    None for none; ``notes``: the command also takes an EQUATION, and --eps, --force belong to
    the Duffing oscillator it defaults to)."""
    need = " (required)" if required else ""
    whose = "without EQUATION, Duffing's " if notes else ""
    p.add_argument("--eps", type=_real, required=required, metavar="EPS",
                   help=f"{whose}ε, the cubic stiffness coefficient (dimensionless; > 0 "
                   f"hardens, < 0 softens){need}")
    if force:
        p.add_argument("--force", type=_real, required=required, metavar="F",
                       help=f"{whose}f, the drive amplitude, in units of the linear stiffness "
                       f"× length (q is dimensionless){need}")
    if omega is not None:
        _flag_omega(p, omega_forms, f"{omega}, in units of the linear natural frequency "
                    f"ω0{need}", required=required)
    if Q == "required":
        p.add_argument("--Q", type=_quality, required=True, metavar="Q",
                       help="quality factor Q > 0 of the damping q'/Q (finite; required)")
    elif Q == "optional":
        p.add_argument("--Q", type=_quality, default=math.inf, metavar="Q",
                       help="quality factor Q > 0 of the damping q'/Q (default inf: undamped)")


def dynamics_json(d, names: list[str]) -> dict:
    """The bifurcations and attractors of an :class:`analysis.attractors.Dynamics` as data
    (``names``: the coordinates), for ``response`` with and without SYSTEM."""
    def multipliers(ms) -> list:
        return [[m.real, m.imag] for m in ms]

    return {
        "bifurcations": [
            {"kind": b.kind, "omega": b.omega, "branch": b.piece,
             "amplitude": dict(zip(names, b.amplitudes, strict=True)),
             "multipliers": multipliers(b.multipliers),
             "moduli": [abs(m) for m in b.multipliers],
             "crossing_residual": b.residual, "stable_side": b.stable_side}
            for b in d.bifurcations],
        "attractors": [
            {"omega": a.omega, "interval": list(a.interval), "why": a.why, "kind": a.kind,
             "period": a.period, "second_frequency": a.second_frequency,
             "power_on_lines": a.power_in_lines,
             "lines": {n: [{"frequency": f, "amplitude": amp} for f, amp in ls]
                       for n, ls in zip(names, a.lines, strict=False)},
             "range": {n: list(r) for n, r in zip(names, a.ranges, strict=False)},
             "from_orbit": dict(zip(names, a.start_amplitudes, strict=True)),
             "transient_periods": a.transient, "recorded_periods": a.periods}
            for a in d.attractors],
        "unstable_intervals": [list(g) for g in d.unstable_intervals],
    }


def dynamics_lines(data: dict) -> list[str]:
    """The table lines of :func:`dynamics_json`'s bifurcations and attractors."""
    lines = []
    for b in data["bifurcations"]:
        top = max(b["moduli"])
        lines.append(f"  {b['kind'].replace('_', '-')} at w = {b['omega']:.8f} (branch "
                     f"{b['branch'] + 1}, " + ", ".join(
                         f"{n} {r:.4g}" for n, r in b["amplitude"].items())
                     + f"; largest |mu| {top:.6g}; stable side: {b['stable_side']})")
    for g in data["unstable_intervals"]:
        lines.append(f"  no stable period-1 orbit for w in {interval(*g, 6)}")
    for a in data["attractors"]:
        extra = (f", second frequency {a['second_frequency']:.6g} (ratio "
                 f"{a['second_frequency'] / a['omega']:.6g})"
                 if a["second_frequency"] is not None else "")
        lines.append(f"  attractor at w = {a['omega']:.6g} ({a['why']}): {a['kind']}{extra}; "
                     f"after {a['transient_periods']} periods, over {a['recorded_periods']}")
        for n, ls in a["lines"].items():
            lo, hi = a["range"][n]
            lines.append(f"    {n} in {interval(lo, hi)}, lines: " + ", ".join(
                f"{e['frequency']:.5g} ({e['amplitude']:.3g})" for e in ls[:6]))
    return lines
