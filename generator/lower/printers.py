"""Printers: SymPy expressions to numba-ready Python source, exact rationals to LaTeX.

Templates never see a SymPy object: everything reaches them through these functions.
"""

from __future__ import annotations

import functools
import itertools
import keyword
import math

import sympy as sp
from sympy.printing.latex import LatexPrinter as SympyLatexPrinter
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import PythonCodePrinter

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
        """The polynomial from its terms, bracketed: ``(0.375*alpha**2 - 0.25)``."""
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


EPS = sp.Symbol("eps")
# NOTE: a user's small parameter, named eps in the equation, is ε in LaTeX.


class LatexPrinter(SympyLatexPrinter):
    """SymPy's LaTeX with ε for ``eps`` and a :class:`Coefficient` printed from its terms:
    ``\frac{3}{8} \alpha^{2} - \frac{1}{4}`` (digits grouped, :func:`latex_rational`)."""

    def __init__(self, stack: bool = True) -> None:
        super().__init__({"symbol_names": {EPS: r"\varepsilon"}})
        self.stack = stack  # long integers stacked in lines (never in a table's cell)

    def _print_Symbol(self, expr: sp.Symbol, style: str = "plain") -> str:
        """ε and φ as ``\\varepsilon``, ``\\varphi`` whatever the symbol's assumptions: one
        ε in every document (a user's ``eps``, the notes' ``epsilon``)."""
        if expr.name in LATEX_NAMES:
            return LATEX_NAMES[expr.name]
        return super()._print_Symbol(expr, style)

    def _print_Coefficient(self, expr: Coefficient) -> str:
        out = []
        for powers, (p, q) in expr.terms:
            mono = " ".join(_latex_name(n) if e == 1 else f"{_latex_name(n)}^{{{e}}}"
                            for n, e in powers)
            number = latex_fraction(abs(p), q, self.stack)
            body = mono if number == "1" and mono else f"{number} {mono}".strip()
            out.append(("- " if p < 0 else "+ ") + body)
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else "-" + text[2:]


LATEX_NAMES = {"eps": r"\varepsilon", "epsilon": r"\varepsilon", "phi": r"\varphi"}
# NOTE: the names every LaTeX document spells one way (the small parameter, the phase).


@functools.cache
def _latex_name(name: str) -> str:
    """The LaTeX of a parameter's name (``alpha`` → ``\\alpha``, ``w0`` → ``w_{0}``)."""
    return LatexPrinter().doprint(sp.Symbol(name))


def latex_equation(equation: Equation) -> str:
    """An equation of motion as mathematics, both sides as written, the derivatives dotted:
    ``\\ddot{q} + q = \\varepsilon \\left(1 - q^{2}\\right) \\dot{q}``."""
    name = latex_expr(equation.coordinate)
    dotted = {equation.derivatives[1]: sp.Symbol(rf"\dot{{{name}}}"),
              equation.derivatives[2]: sp.Symbol(rf"\ddot{{{name}}}")}
    return (f"{latex_expr(equation.lhs.xreplace(dotted))} = "
            f"{latex_expr(equation.rhs.xreplace(dotted))}")


def latex_expr(expr: sp.Basic) -> str:
    """LaTeX of short symbolic factors (powers of A, ε, θ₀) and of exact coefficients."""
    return LatexPrinter().doprint(expr)
