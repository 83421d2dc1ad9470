"""Printers: SymPy expressions to numba-ready Python source, exact rationals to LaTeX.

Templates never see a SymPy object: everything reaches them through these functions.
"""

from __future__ import annotations

import functools
import itertools
import keyword
import math
import re

import sympy as sp
from sympy.printing.latex import LatexPrinter as SympyLatexPrinter
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import PythonCodePrinter
from sympy.printing.str import StrPrinter

from ..derive.equation import Equation
from ..errors import InputError

Terms = tuple[tuple[tuple[tuple[str, int], ...], tuple[int, int]], ...]
# an exact polynomial in the parameters: ((name, power), …) (names sorted, powers ≥ 1; () the
# constant) with its rational (p, q), in SymPy's order of terms


class Coefficient(sp.Symbol):
    """An exact coefficient that is a polynomial in the symbolic parameters (``3α²/8 + 15/32``),
    kept as one atom of the expression tree: SymPy never expands, compares or re-sorts it, and
    the printers print it from its terms (a series over ``QQ[α]`` at order 30 has ~30 000 of
    them; through SymPy's arithmetic and printers they took minutes).  Its name is SymPy's
    spelling of the polynomial, so ``str`` reads as before and equal terms are one atom."""

    terms: Terms

    def __new__(cls, terms: Terms) -> Coefficient:
        obj = super().__new__(cls, polynomial_text(terms))
        obj.terms = terms
        return obj


class _ExactText(StrPrinter):
    """SymPy's ``str`` that reads back as the value: a :class:`Coefficient` of two terms or
    more is bracketed inside any expression (``sqrt(130)*(-9261*A**4/43264 - …)/10``), one of
    a single term wherever SymPy would bracket an operand (a denominator, a power's base)."""

    def _print_Coefficient(self, expr: Coefficient) -> str:
        return f"({expr.name})" if len(expr.terms) > 1 else expr.name

    def parenthesize(self, item: sp.Basic, level: int, strict: bool = False) -> str:
        if isinstance(item, Coefficient):
            text = self._print(item)
            return text if text.isidentifier() or len(item.terms) > 1 else f"({text})"
        return super().parenthesize(item, level, strict)


def exact_text(expr: sp.Basic) -> str:
    """The text of an exact expression for a module's ``*_EXACT`` constants: SymPy's spelling,
    each :class:`Coefficient` bracketed where it is not the whole (``sympify`` reads it back
    as the value)."""
    return expr.name if isinstance(expr, Coefficient) else _ExactText().doprint(expr)


def _monomial(powers: tuple[tuple[str, int], ...], power: str = "**") -> str:
    return "*".join(n if e == 1 else f"{n}{power}{e}" for n, e in powers)


def polynomial_text(terms: Terms) -> str:
    """SymPy's ``str`` of a polynomial given by its terms (``3*alpha**2/8 - 1/4``)."""
    out = []
    for powers, (p, q) in terms:
        body = _monomial(powers)
        if body:
            body = (body if abs(p) == 1 else f"{abs(p)}*{body}") + (f"/{q}" if q != 1 else "")
        else:
            body = f"{abs(p)}/{q}" if q != 1 else f"{abs(p)}"
        out.append(("- " if p < 0 else "+ ") + body)
    text = " ".join(out) or "+ 0"
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


def exact(ground: object, c: object) -> sp.Expr:
    """An exact coefficient of ``ground`` (:class:`algebra.series.Ground`) as an expression: a
    ``Rational`` where it is a number, else a :class:`Coefficient`, built from FLINT's terms
    (no SymPy arithmetic)."""
    items = ground.terms(c)
    if all(not powers for powers, _ in items):
        v = items[0][1] if items else 0
        return sp.Rational(int(v.p), int(v.q)) if items else sp.Integer(0)
    names = sorted({n for powers, _ in items for n, _ in powers})

    def order(term: tuple) -> tuple:  # SymPy's: lex on the names (sorted), descending
        powers = dict(term[0])
        return tuple(-powers.get(n, 0) for n in names)

    return Coefficient(tuple((powers, (int(v.p), int(v.q)))
                             for powers, v in sorted(items, key=order)))


def scaled(factor: sp.Expr, c: sp.Expr) -> sp.Expr:
    """``factor · c``; a rational ``factor`` taken into a :class:`Coefficient`'s terms
    (``2·(3A²/32)`` is ``3A²/16``), where SymPy would keep the product."""
    if not (isinstance(c, Coefficient) and factor.is_Rational):
        return factor * c
    return Coefficient(tuple(
        (powers, ((r := sp.Rational(p, q) * factor).p, r.q)) for powers, (p, q) in c.terms))


ESTRIN_FROM = 8
# NOTE: polynomials of this many coefficients or more are split by Estrin's scheme (Knuth,
# TAOCP 2, §4.6.4): Horner's chain of n dependent multiply-adds runs at the FPU's latency in
# the ufuncs, which numba calls point by point; the split chain is ~2 log2 n long.  Degree 43
# as a scalar ufunc: 29 ns per point by Horner, 8 ns split (the `_into` loops, vectorised
# across points, hide the latency either way).


class Polynomial(sp.Function):
    """``Σ c_j x^j`` as one node of the expression tree, arguments ``(x, c_0, …, c_n)``: SymPy
    never expands, re-sorts or re-nests it (at order 60 its Horner form as SymPy's Add and Mul
    took most of a `generate`); :class:`NumbaPrinter` writes it in Horner's form, split by
    Estrin's scheme from :data:`ESTRIN_FROM` coefficients."""

    precedence = PRECEDENCE["Add"]  # printed as a sum: bracketed inside a product

    @classmethod
    def eval(cls, *args: sp.Expr) -> None:
        """``None`` always: the node stays as built."""
        return None  # never evaluated: the node is the form


class NumbaPrinter(PythonCodePrinter):
    """Python source that numba compiles in nopython mode (``math`` functions, float literals).

    Rationals print as the correctly rounded double (Python's ``int / int`` is correctly
    rounded), so a generated constant differs from the exact one by at most half an ulp.

    >>> NumbaPrinter().doprint(sp.Rational(3, 8) * sp.Symbol("x") + sp.cos(sp.Symbol("s")))
    '(0.375)*x + math.cos(s)'
    """

    printmethod = "_numbacode"

    def _print_Rational(self, expr: sp.Rational) -> str:
        """``\\frac`` of grouped digits (:func:`latex_fraction`)."""
        return repr(int(expr.p) / int(expr.q))

    def _print_Half(self, expr: sp.Rational) -> str:
        return "0.5"

    def _print_Polynomial(self, expr: Polynomial) -> str:
        """``c_0 + x*(c_1 + x*(…))``, from :data:`ESTRIN_FROM` coefficients
        ``L(x) + x**m*(H(x))`` with ``m`` the largest power of two below the length, each half
        split again; zero coefficients skipped (``c_0 + x**2*(c_2 + …)``)."""
        x = self.parenthesize(expr.args[0], PRECEDENCE["Pow"])
        shift, body = self._polynomial_terms(x, list(expr.args[1:]))
        return " + ".join(_times(x, shift, body)).replace(" + -", " - ")

    def _polynomial_terms(self, x: str, coeffs: list[sp.Expr]) -> tuple[int, list[str]]:
        """``Σ c_j x^j`` as ``x**k`` times a sum: ``(k, its signed terms)``."""
        nonzero = [j for j, c in enumerate(coeffs) if c != 0]
        if not nonzero:
            return 0, []
        if len(coeffs) >= ESTRIN_FROM:
            m = 1 << ((len(coeffs) - 1).bit_length() - 1)
            (k_low, low), (k_high, high) = (self._polynomial_terms(x, coeffs[:m]),
                                            self._polynomial_terms(x, coeffs[m:]))
            if not low:
                return m + k_high, high
            return 0, _times(x, k_low, low) + _times(x, m + k_high, high)
        j = nonzero[0]
        c = coeffs[j]
        head = self._print(c) if c.is_Number else self.parenthesize(c, PRECEDENCE["Mul"],
                                                                      strict=True)
        body = [head]
        if len(nonzero) > 1:
            k = nonzero[1]
            shift, rest = self._polynomial_terms(x, coeffs[k:])
            body += _times(x, k - j + shift, rest)
        return j, body

    def _print_Coefficient(self, expr: Coefficient) -> str:
        """The polynomial from its terms, bracketed: ``(0.375*alpha**2 - 0.25)``; of two terms
        or more, in Horner's form in its first name (:class:`Polynomial`'s printing), each
        coefficient in the others likewise: ``(A*(0.333 + A*(alpha*(-0.031) + …)))``.  No
        powers: a third fewer operations for numba to type and lower, and LLVM's own form."""
        names = sorted({n for powers, _ in expr.terms for n, _ in powers})
        if names and len(expr.terms) > 1:
            by_power: dict[int, list] = {}
            for powers, pq in expr.terms:
                rest = dict(powers)
                by_power.setdefault(rest.pop(names[0], 0), []).append((tuple(rest.items()), pq))
            coeffs: list[sp.Expr] = [sp.Integer(0)] * (1 + max(by_power))
            for k, terms in by_power.items():
                (powers, (p, q)), *more = terms
                coeffs[k] = Coefficient(tuple(terms)) if powers or more else sp.Rational(p, q)
            x = identifier(names[0])
            shift, body = self._polynomial_terms(x, coeffs)
            return "(" + " + ".join(_times(x, shift, body)).replace(" + -", " - ") + ")"
        out = []
        for powers, (p, q) in expr.terms:
            mono = "*".join(identifier(n) if e == 1 else f"{identifier(n)}**{e}"
                            for n, e in powers)
            number = repr(abs(p) / q)
            body = mono if number == "1.0" and mono else (f"{number}*{mono}" if mono else number)
            out.append(("- " if p < 0 else "+ ") + body)
        text = " ".join(out)
        return "(" + (text[2:] if text.startswith("+ ") else "-" + text[2:]) + ")"

    def _print_NotNaN(self, expr: sp.Basic) -> str:  # lower.NotNaN: isnan is a quiet test
        return f"not math.isnan({self._print(expr.args[0])})"

    def _print_Finite(self, expr: sp.Basic) -> str:  # lower.Finite: isnan, isinf are quiet
        v = self._print(expr.args[0])
        return f"(not math.isnan({v}) and not math.isinf({v}))"


def _times(x: str, k: int, body: list[str]) -> list[str]:
    """The terms ``body`` (a sum) times ``x**k``: one term, or the bracketed sum times it."""
    if not body or k == 0:
        return body
    power = x if k == 1 else f"{x}**{k}"
    if len(body) == 1:  # one coefficient, printed at Mul's precedence
        term = body[0]
        return [power if term == "1" else f"-{power}" if term == "-1" else f"{term}*{power}"]
    return [f"{power}*(" + " + ".join(body).replace(" + -", " - ") + ")"]


class SimdPrinter(NumbaPrinter):
    """:class:`NumbaPrinter` with ``cos``/``sin`` as the generated module's branch-free
    ``_cos``/``_sin``, which LLVM vectorises (``math.cos`` stays a scalar libm call)."""

    def _print_cos(self, expr: sp.cos) -> str:
        return f"_cos({self._print(expr.args[0])})"

    def _print_sin(self, expr: sp.sin) -> str:
        return f"_sin({self._print(expr.args[0])})"


def identifier(name: str) -> str:
    """``name`` if it may appear in generated code: a Python identifier, not a keyword.

    >>> identifier("theta0")
    'theta0'
    """
    if not isinstance(name, str) or not name.isidentifier() or keyword.iskeyword(name):
        raise InputError(f"name {name!r}: not a valid Python identifier for generated code")
    if name.startswith("__"):
        raise InputError(f"name {name!r}: dunder names are reserved")
    return name


def pycode(expr: sp.Basic, simd: bool = False) -> str:
    """One expression as numba source (``simd``: vectorisable ``_cos``/``_sin``)."""
    return (SimdPrinter if simd else NumbaPrinter)({"fully_qualified_modules": True}).doprint(expr)


LATEX_LINE_DIGITS = 30
# NOTE: 30 digits in groups of 3 set ~181pt wide at 11pt; with a minus sign they fit the tables'
# 0.42\linewidth columns (~203pt with 2cm margins), so longer integers go on several lines.


def latex_digits(n: int, stack: bool = True) -> str:
    r"""A non-negative integer in groups of 3 digits (thin spaces); longer than
    ``LATEX_LINE_DIGITS`` and ``stack``, it is stacked in right-aligned lines broken only
    between groups, the lines differing by at most one group (a table's cell never stacks:
    its ``\padmath`` shrinks what is wider than the column, so a number reads as one).

    >>> latex_digits(57594037927936)
    '57\\,594\\,037\\,927\\,936'
    """
    text = str(n)
    if len(text) <= 4:
        return text  # four digits read at a glance (siunitx's default minimum for grouping)
    head = len(text) % 3 or 3
    groups = [text[:head], *(text[i:i + 3] for i in range(head, len(text), 3))]
    lines = math.ceil(len(groups) / (LATEX_LINE_DIGITS // 3)) if stack else 1
    if lines == 1:
        return r"\,".join(groups)
    cuts = [i * len(groups) // lines for i in range(lines + 1)]
    rows = [r"\,".join(groups[a:b]) for a, b in itertools.pairwise(cuts)]
    # right-aligned, so the groups of every line stand in columns under one another
    return r"\begin{array}{@{}r@{}}" + r"\\".join(rows) + r"\end{array}"


def latex_rational(r: sp.Rational, stack: bool = True) -> str:
    """An exact rational for LaTeX math: ``\\frac`` of grouped digits (:func:`latex_digits`).

    >>> latex_rational(sp.Rational(-21, 256))
    '-\\\\frac{21}{256}'
    """
    r = sp.Rational(r)
    return latex_fraction(int(r.p), int(r.q), stack)


def latex_fraction(p: int, q: int, stack: bool = True) -> str:
    """:func:`latex_rational` of ``p/q`` in lowest terms, ``q > 0`` (plain integers: no
    SymPy number on the way)."""
    sign = "-" if p < 0 else ""
    top, bottom = latex_digits(abs(p), stack), latex_digits(q, stack)
    return sign + (top if q == 1 else rf"\frac{{{top}}}{{{bottom}}}")


def latex_coefficient(c: sp.Expr, stack: bool = True) -> str:
    """:func:`latex_rational` for a number, :func:`latex_expr` for a polynomial in parameters."""
    return latex_rational(c, stack) if c.is_Rational else LatexPrinter(stack).doprint(c)


EPS_FIRST = sp.Symbol(" eps")
# NOTE: ε under a name that sorts before every other (a space comes before the letters):
# SymPy orders a product's factors by name, so ``ε A_1^3`` and not ``A_1^3 ε``.


class LatexPrinter(SympyLatexPrinter):
    r"""SymPy's LaTeX with ε for ``eps``, first in every product; ``\cos 2\varphi`` for a
    multiple of one symbol; a :class:`Coefficient` printed from its terms:
    ``\frac{3}{8} \alpha^{2} - \frac{1}{4}`` (digits grouped, :func:`latex_rational`)."""

    def __init__(self, stack: bool = False, names: dict | None = None) -> None:
        super().__init__({"symbol_names": {EPS_FIRST: r"\varepsilon", **(names or {})}})
        self.stack = stack  # long integers stacked in lines (no document does: they scale)

    def doprint(self, expr: sp.Basic) -> str:
        """The LaTeX of ``expr``, its ε renamed to :data:`EPS_FIRST`."""
        return super().doprint(_eps_first(expr))

    def _print_Symbol(self, expr: sp.Symbol, style: str = "plain") -> str:
        """φ as ``\\varphi`` whatever the symbol's assumptions (the notes' phase)."""
        if expr.name in LATEX_NAMES:
            return LATEX_NAMES[expr.name]
        return super()._print_Symbol(expr, style)

    def _print_Integer(self, expr: sp.Integer) -> str:
        """Digits in groups of 3 (:func:`latex_digits`), as in the tables."""
        return ("-" if expr < 0 else "") + latex_digits(abs(int(expr)), self.stack)

    def _print_Rational(self, expr: sp.Rational) -> str:
        """``\\frac`` of grouped digits (:func:`latex_fraction`)."""
        return latex_fraction(int(expr.p), int(expr.q), self.stack)

    def _print_cos(self, expr: sp.cos, exp: str | None = None) -> str:
        return self._trig("cos", expr, exp)

    def _print_sin(self, expr: sp.sin, exp: str | None = None) -> str:
        return self._trig("sin", expr, exp)

    def _trig(self, name: str, expr: sp.Function, exp: str | None) -> str:
        r"""``\cos\varphi``, ``\cos 2\varphi`` (never ``\cos 1\varphi``): a symbol or an
        integer multiple of one needs no brackets; any other argument is bracketed."""
        head = rf"\{name}" if exp is None else rf"\{name}^{{{exp}}}"
        n, rest = expr.args[0].as_coeff_Mul()
        if not (rest.is_Symbol and n.is_Integer and n > 0):
            return rf"{head}{{\left({self._print(expr.args[0])} \right)}}"
        return f"{head}{self._print(rest)}" if n == 1 else f"{head} {n}{self._print(rest)}"

    def _print_Coefficient(self, expr: Coefficient) -> str:
        out = []
        for powers, (p, q) in expr.terms:
            mono = " ".join(_latex_name(n) if e == 1 else f"{_latex_name(n)}^{{{e}}}"
                            for n, e in sorted(powers, key=lambda t: t[0] not in SMALL_NAMES))
            number = latex_fraction(abs(p), q, self.stack)
            body = mono if number == "1" and mono else f"{number} {mono}".strip()
            out.append(("- " if p < 0 else "+ ") + body)
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else "-" + text[2:]


def _eps_first(expr: sp.Basic) -> sp.Basic:
    """``expr`` with its ε (any symbol of :data:`SMALL_NAMES`) renamed to :data:`EPS_FIRST`."""
    small = {s: EPS_FIRST for s in getattr(expr, "free_symbols", ()) if s.name in SMALL_NAMES}
    return expr.xreplace(small) if small else expr


SMALL_NAMES = frozenset({"eps", "epsilon"})
# NOTE: the small parameter's names (a user's eps, the notes' epsilon): ε in every document.
LATEX_NAMES = {"phi": r"\varphi"}
# NOTE: the names every LaTeX document spells one way (the phase; ε is EPS_FIRST's).


@functools.cache
def _latex_name(name: str) -> str:
    """The LaTeX of a parameter's name (``alpha`` → ``\\alpha``, ``w0`` → ``w_{0}``)."""
    return LatexPrinter().doprint(sp.Symbol(name))


def latex_equation(equation: Equation) -> str:
    """An equation of motion as mathematics, both sides as written, the derivatives dotted:
    ``\\ddot{q} + q = \\varepsilon \\dot{q} \\left(1 - q^{2}\\right)``; a side's terms in
    the order q̈, the terms free of ε, the terms in ε."""
    name = latex_expr(equation.coordinate)
    # NOTE: "~" sorts after the letters: q̇ follows the other factors of a product
    first, second = (sp.Symbol(f"~{k}{equation.coordinate}") for k in (1, 2))
    dotted = {equation.derivatives[1]: first, equation.derivatives[2]: second}
    printer = LatexPrinter(names={first: rf"\dot{{{name}}}", second: rf"\ddot{{{name}}}"})

    def side(expr: sp.Expr) -> str:
        terms = sorted(sp.Add.make_args(expr.xreplace(dotted)), key=lambda t: (
            not t.has(second), any(s.name in SMALL_NAMES for s in t.free_symbols)))
        return " ".join(signed_terms(printer, terms)).removeprefix("+ ")

    return f"{side(equation.lhs)} = {side(equation.rhs)}"


def signed_terms(printer: LatexPrinter, terms: list[sp.Expr]) -> list[str]:
    """Each of ``terms`` printed with its sign in front: ``["+ a", "- b"]``."""
    return [f"- {printer.doprint(-t)}" if t.could_extract_minus_sign()
            else f"+ {printer.doprint(t)}" for t in terms]


def latex_expr(expr: sp.Basic) -> str:
    """LaTeX of short symbolic factors (powers of A, ε, θ₀) and of exact coefficients."""
    return LatexPrinter().doprint(expr)


EXACT_WIDTH = 24
DECIMAL_DIGITS = 12
# NOTE: an exact number whose SymPy form is longer than EXACT_WIDTH characters is shown to
# DECIMAL_DIGITS significant digits where people read (tables, LaTeX): a normal mode's
# coefficients in Q(√10441) reach numerators of 90 digits by order 4; the JSON keeps them.


def is_long(c: sp.Expr) -> bool:
    """Whether the exact form of ``c`` is too long to read (over :data:`EXACT_WIDTH`)."""
    return len(sp.sstr(c)) > EXACT_WIDTH


def readable(c: sp.Expr) -> sp.Expr:
    """``c`` itself when its exact form is short, else its decimal (:data:`DECIMAL_DIGITS`
    significant digits; a symbolic parameter stays a symbol).

    >>> readable(sp.Rational(3, 64)), readable(sp.sqrt(sp.Rational(321, 200) - sp.sqrt(10441)/200))
    (3/64, 1.04598945602)
    """
    return sp.N(c, DECIMAL_DIGITS) if is_long(c) else c


def decimal_text(c: sp.Expr) -> str:
    """``c`` to :data:`DECIMAL_DIGITS` significant digits, as text."""
    return sp.sstr(sp.N(c, DECIMAL_DIGITS))


def minimal_polynomial(c: sp.Expr, name: str = "x") -> sp.Expr | None:
    """The minimal polynomial of the algebraic number ``c`` over Q in ``name``, integer
    coefficients; None for a rational (it is its own exact form)."""
    if c.is_Rational:
        return None
    return sp.minimal_polynomial(c, sp.Symbol(name), polys=False)


LINE_EM = 40.0
# NOTE: a display line's width in em: the text block is 170 mm (A4, 2 cm margins), ~44 em at
# 11pt; 4 em are kept for the left side's indentation and the estimate's error.
_TOKEN = re.compile(r"\\[A-Za-z]+|\\.|\d|[A-Za-z]|\s+|.")
_WIDTHS = {"+": 1.2, "-": 1.2, "=": 1.3, "<": 1.3, ">": 1.3, "(": 0.4, ")": 0.4, "[": 0.3,
           "]": 0.3, ",": 0.3, ".": 0.3, "'": 0.3, "|": 0.3, "/": 0.5, "&": 0.0, "~": 0.3}
# NOTE: widths in em of Computer Modern math at text size, with the spacing TeX adds around
# binary operators and relations; a letter or digit is 0.5 em
_COMMANDS = {r"\,": 0.17, r"\;": 0.28, r"\:": 0.22, r"\!": -0.17, r"\quad": 1.0,
             r"\qquad": 2.0, r"\cos": 1.4, r"\sin": 1.1, r"\sinh": 1.6, r"\cosh": 1.9,
             r"\exp": 1.4, r"\log": 1.2, r"\cdot": 0.8, r"\pi": 0.6, r"\colon": 0.5}
_SIZED = {r"\left", r"\right", r"\bigl", r"\bigr", r"\Bigl", r"\Bigr", r"\biggl", r"\biggr"}
_ZERO = {r"\dot", r"\ddot", r"\displaystyle", r"\mathrm", r"\text", r"\operatorname",
         r"\fitmath", r"\tilde", r"\hat", r"\bar"}


def latex_width(tex: str) -> float:
    r"""The width of a LaTeX math fragment in em, estimated (an upper bound for the fragments
    the printers write): a ``\frac`` is as wide as its wider part, scripts are smaller.

    >>> latex_width(r"\frac{3}{8} y^{2}") < latex_width(r"3 / 8 y^{2}")
    True
    """
    tokens = _TOKEN.findall(tex)
    return _group_width(tokens, 0, len(tokens))[0]


def _group_width(tokens: list[str], i: int, end: int) -> tuple[float, int]:
    """The width of ``tokens[i:]`` up to the ``}`` closing this group (or ``end``), and the
    index after it."""
    width = 0.0
    while i < end:
        tok = tokens[i]
        if tok == "}":
            return width, i + 1
        w, i = _atom_width(tokens, i, end)
        width += w
    return width, i


def _atom_width(tokens: list[str], i: int, end: int) -> tuple[float, int]:
    """The width of the atom at ``tokens[i]`` (a group, a command with its arguments, a
    script, one character) and the index after it."""
    tok = tokens[i]
    if tok == "{":
        return _group_width(tokens, i + 1, end)
    if tok in ("^", "_"):
        w, j = _atom_width(tokens, i + 1, end)
        return 0.7 * w, j
    if tok in (r"\frac", r"\dfrac", r"\tfrac"):
        top, j = _atom_width(tokens, i + 1, end)
        bottom, j = _atom_width(tokens, j, end)
        return max(top, bottom) + 0.3, j
    if tok in _SIZED:
        return 0.5, i + 2  # the delimiter that follows
    if tok in _ZERO:
        return 0.0, i + 1
    if tok.isspace():
        return 0.0, i + 1
    if tok.startswith("\\"):
        return _COMMANDS.get(tok, 0.6), i + 1
    return _WIDTHS.get(tok, 0.5), i + 1


def latex_lines(items: list[str], width: float = LINE_EM) -> list[str]:
    r"""``items`` (a sum's signed terms, each ``"+ …"`` or ``"- …"``) packed greedily into lines
    at most ``width`` em wide: several terms per line, a short sum on one line.  A term wider
    than a line stands on its own, in ``\fitmath`` (the preamble's: scaled down to the line,
    never broken, so no number is split).

    >>> latex_lines(["a", "+ b", "- c"], 3.0)
    ['a + b', '- c']
    """
    lines: list[list[str]] = []
    used = width
    for item in items:
        w = latex_width(item)
        if w > width:
            sign, body = (item[0], item[2:]) if item[:2] in ("+ ", "- ") else ("", item)
            lines.append([f"{sign} \\fitmath{{{width:.0f}em}}{{{body}}}".strip()])
            used = width
        elif used + w > width:
            lines.append([item])
            used = w
        else:
            lines[-1].append(item)
            used += w
    return [" ".join(line) for line in lines]


def latex_sum_items(expr: sp.Expr, width: float = LINE_EM) -> list[str]:
    r"""``expr`` as items for :func:`latex_lines`: itself (each term over its denominator), if
    it fits a line and its terms have no common factor of degree 2 or more; else the common
    factor over the denominator in front, ``\frac{\varepsilon A_1^{3}}{D}\Bigl(``, then the
    signed terms of the rest, the last closing ``\Bigr)`` (a fraction is never broken; a sum
    breaks between its terms).

    >>> latex_sum_items(sp.sympify("eps**2*A**3*w + 3*eps*A**4"))
    ['\\varepsilon A^{3} \\Bigl(', '\\varepsilon w', '+ 3 A\\Bigr)']
    """
    expr = _eps_first(expr)
    whole = latex_expr(_distributed(expr))
    num, den = sp.fraction(sp.together(expr))
    terms = sp.Add.make_args(sp.expand(num))
    if len(terms) == 1:
        return [whole]
    common = sp.Mul(*(f for f in sp.Mul.make_args(sp.factor_terms(sp.Add(*terms)))
                      if not f.is_Add))
    degree = sum(e for base, e in common.as_powers_dict().items() if not base.is_Number)
    if degree < 2 and latex_width(whole) <= width:
        return [whole]
    if degree < 2:
        common = sp.Integer(1)
    rest = sp.expand(sp.Add(*terms) / common).as_ordered_terms()
    items = signed_terms(LatexPrinter(), rest)
    items[0] = items[0].removeprefix("+ ")
    head = common / den
    if head == 1:
        return items
    items[-1] += r"\Bigr)"
    return [latex_expr(head) + r" \Bigl(", *items]


def _distributed(expr: sp.Expr) -> sp.Expr:
    """``expr`` as a sum of single terms, each over its own denominator, the denominators
    kept factored (``(a/8 + b/4)/r`` → ``a/(8r) + b/(4r)``: no fraction inside a fraction)."""
    out = []
    for term in sp.Add.make_args(expr):
        num, den = sp.fraction(sp.together(term))
        out += [t / den for t in sp.Add.make_args(sp.expand(num))]
    return sp.Add(*out)


def _edge(text: str) -> str:
    """An orbit edge (30 digits) as a reader reads it: 12 significant digits.

    >>> _edge("9.86960440108935861883449099988"), _edge("-1.0")
    ('9.86960440109', '-1')
    """
    return f"{float(text):.12g}"


def latex_validity(valid, y: str) -> str:
    """Where a free oscillator's series holds, as a LaTeX sentence: the range of ``y`` over
    which its periodic orbits exist (``valid.orbit``) and the radius of convergence of its
    series (:class:`derive.lindstedt.Validity`, exact or estimated)."""
    o = valid.orbit
    lo = "" if math.isinf(o.lower) else f"{_edge(o.lower_text)} < "
    hi = "" if math.isinf(o.upper) else f" < {_edge(o.upper_text)}"
    orbits = ("the range of the periodic orbits was not computed" if not o.known else
              f"periodic orbits exist for ${lo}{y}{hi}$" if lo or hi else
              f"periodic orbits exist for every ${y}$ searched")
    if valid.exact is not None:
        radius = (f"the series converge for $|{y}| < {sp.latex(valid.exact)}$ (the radius of "
                  "convergence, exact)")
    elif valid.radius is not None:
        radius = (f"the series of $T$ converges for $|{y}| < {valid.radius:.6g}$ (the radius "
                  f"of convergence estimated from the $\\tau_j$ to order {valid.order}, spread "
                  f"${valid.spread:.2g}$)")
    else:
        radius = "no radius of convergence is estimated"
    return (f"Validity: {orbits}; {radius}.  The truncated sums hold only where both "
            "do.")
