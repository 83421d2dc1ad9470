"""Printers: SymPy expressions to numba-ready Python source, exact rationals to LaTeX.

Templates never see a SymPy object: everything reaches them through these functions.
"""

from __future__ import annotations

import keyword

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from .errors import InputError


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


LATEX_FRAC_DIGITS = 30
# NOTE: a \frac wider than ~30 digits no longer fits a line; longer numbers wrap via seqsplit.


def latex_rational(r: sp.Rational, wrap: bool = True) -> str:
    """An exact rational for LaTeX: ``\\frac`` when it fits a line, else a wrapping digit run.

    >>> latex_rational(sp.Rational(-21, 256))
    '-\\\\frac{21}{256}'
    """
    r = sp.Rational(r)
    p, q = int(r.p), int(r.q)
    sign = "-" if p < 0 else ""
    p = abs(p)
    if q == 1:
        body = str(p)
        if len(body) <= LATEX_FRAC_DIGITS or not wrap:
            return f"{sign}{body}"
    elif len(str(p)) + len(str(q)) <= LATEX_FRAC_DIGITS or not wrap:
        return f"{sign}\\frac{{{p}}}{{{q}}}"
    text = f"{p}/{q}" if q != 1 else str(p)
    return f"{sign}\\parbox[t]{{0.5\\linewidth}}{{\\raggedright\\seqsplit{{{text}}}}}"


def latex_expr(expr: sp.Basic) -> str:
    """SymPy's LaTeX for short symbolic factors (powers of A, ε, θ₀)."""
    return sp.latex(expr)
