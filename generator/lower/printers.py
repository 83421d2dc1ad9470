"""Printers: SymPy expressions to numba-ready Python source, exact rationals to LaTeX.

Templates never see a SymPy object: everything reaches them through these functions.
"""

from __future__ import annotations

import itertools
import keyword
import math

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from ..errors import InputError


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

    def _print_NotNaN(self, expr: sp.Basic) -> str:  # lower.NotNaN: isnan is a quiet test
        return f"not math.isnan({self._print(expr.args[0])})"

    def _print_Finite(self, expr: sp.Basic) -> str:  # lower.Finite: isnan, isinf are quiet
        v = self._print(expr.args[0])
        return f"(not math.isnan({v}) and not math.isinf({v}))"


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
    sign = "-" if r < 0 else ""
    p, q = latex_digits(abs(int(r.p)), stack), latex_digits(int(r.q), stack)
    return sign + (p if q == "1" else rf"\frac{{{p}}}{{{q}}}")


def latex_coefficient(c: sp.Expr, stack: bool = True) -> str:
    """:func:`latex_rational` for a number, SymPy's LaTeX for a polynomial in parameters."""
    return latex_rational(c, stack) if c.is_Rational else sp.latex(c)


EPS = sp.Symbol("eps")
# NOTE: a user's small parameter, named eps in the equation, is ε in LaTeX.


def latex_expr(expr: sp.Basic) -> str:
    """SymPy's LaTeX for short symbolic factors (powers of A, ε, θ₀)."""
    return sp.latex(expr, symbol_names={EPS: r"\varepsilon"})
