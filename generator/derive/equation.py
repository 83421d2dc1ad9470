"""User text -> SymPy, through a whitelist walker over Python's ``ast`` (nothing is evaluated).

An equation of motion reads like ``q'' + q + eps*(alpha*q**2 + q**3) = 0``: the coordinate is
the one name written with primes (``q'`` and ``q''`` are its derivatives in ``t``), ``t`` is
time, ``eps`` the small parameter, and every other name a parameter.  The walker accepts
numbers, names, ``+ - * / **`` with integer exponents, and calls of the analytic functions in
:data:`FUNCTIONS` on one argument; anything else (attributes, subscripts, lambdas, strings,
comprehensions, keywords, non-integer or huge powers) is refused with its column.  Numbers stay
exact: ``0.1`` is ``1/10``.

    >>> parse_equation("q'' + q + eps*q**3 = 0").expression
    eps*q**3 + q + q''
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from ..errors import InputError

FUNCTIONS = {
    "sin": sp.sin, "cos": sp.cos, "exp": sp.exp, "sinh": sp.sinh, "cosh": sp.cosh,
    "tanh": sp.tanh, "log": sp.log, "sqrt": sp.sqrt,
}
# NOTE: analytic at the equilibrium as long as log's and sqrt's argument is positive there
# (``log(1 + q)``, ``sqrt(1 + q**2)``); :mod:`models` checks that before expanding.
TIME, SMALL = "t", "eps"
RESERVED = frozenset(FUNCTIONS) | {"pi", "E", "I", "oo", "nan", "zoo"}
# NOTE: names SymPy users read as constants are refused rather than taken as parameters.
MAX_TEXT = 2000
MAX_DEPTH = 60
MAX_POWER = 64
MAX_DIGITS = 40
MAX_NAME = 32
MAX_MAGNITUDE = 300
# NOTE: bounds that keep a hostile text from costing time or memory before any algebra
# (``q**10**10``, ``9**9**9``, ``((2**64)**64)**64``, ``(q**64)**64``, 10⁵ nested brackets):
# powers, degrees (a bound carried up the tree) and numbers (|log10| ≤ MAX_MAGNITUDE) are
# checked before they are built; far above any oscillator's needs.
ALLOWED = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_+-*/().'= ")
# NOTE: nothing else can reach a parse, so no comment (#), quote, brace or backslash of the
# user's ever reaches a banner, a docstring or a LaTeX file.
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_PRIMED = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)('+)")


@dataclass(frozen=True)
class Equation:
    """A parsed equation of motion ``expression = 0`` (left side minus right side).

    ``derivatives[k]`` is the symbol standing for the k-th time derivative of the coordinate
    (``derivatives[0]`` is the coordinate itself); ``parameters`` are the other names, sorted.
    """

    text: str
    expression: sp.Expr
    derivatives: tuple[sp.Symbol, ...]
    time: sp.Symbol
    small: sp.Symbol | None
    parameters: tuple[sp.Symbol, ...]
    lhs: sp.Expr = sp.S.Zero  # the two sides as written (for typesetting)
    rhs: sp.Expr = sp.S.Zero

    @property
    def coordinate(self) -> sp.Symbol:
        """The coordinate's symbol (``derivatives[0]``)."""
        return self.derivatives[0]


def _fail(text: str, column: int, what: str) -> InputError:
    return InputError(f"equation {text!r}, column {column + 1}: {what}")


def _check_characters(text: str, what: str) -> None:
    if len(text) > MAX_TEXT:
        raise InputError(f"{what}: {len(text)} characters, above the limit {MAX_TEXT}")
    for i, ch in enumerate(text):
        if ch not in ALLOWED:
            raise InputError(f"{what} {text!r}, column {i + 1}: character {ch!r} is not allowed "
                             "(ASCII letters, digits, + - * / ( ) . ' = and spaces)")


def _check_names(text: str, source: str, what: str) -> None:
    for match in _NAME.finditer(source):
        name, col = match.group(), match.start()
        if col and (source[col - 1].isdigit() or source[col - 1] == "."):
            continue  # part of a number such as 1e3
        if name.startswith("_") or name.endswith("_"):
            raise InputError(f"{what} {text!r}, column {col + 1}: name {name!r} may not start "
                             "or end with '_'")
        if len(name) > MAX_NAME:
            raise InputError(f"{what} {text!r}, column {col + 1}: name {name[:12]}… is longer "
                             f"than {MAX_NAME} characters")


class _Walker:
    """Turns a whitelisted ``ast`` expression into SymPy, or raises naming the column."""

    def __init__(self, text: str, offset: int, what: str) -> None:
        self.text, self.offset, self.what = text, offset, what
        self.names: dict[str, int] = {}  # name -> first column

    def fail(self, node: ast.AST, why: str) -> InputError:
        col = self.offset + getattr(node, "col_offset", 0)
        return InputError(f"{self.what} {self.text!r}, column {col + 1}: {why}")

    def walk(self, node: ast.AST, depth: int = 0) -> tuple[sp.Expr, int]:
        """The node's expression and a bound on its degree in the names (0 for a number)."""
        if depth > MAX_DEPTH:
            raise self.fail(node, f"nested deeper than {MAX_DEPTH} levels")
        handler = getattr(self, f"_{type(node).__name__}", None)
        if handler is None:
            raise self.fail(node, f"{_describe(node)} is not allowed here")
        expr, degree = handler(node, depth + 1)
        if degree > MAX_POWER:
            raise self.fail(node, f"degree {degree} is above the limit {MAX_POWER}")
        return expr, degree

    def _Expression(self, node: ast.Expression, depth: int) -> tuple[sp.Expr, int]:
        return self.walk(node.body, depth)

    def _Constant(self, node: ast.Constant, depth: int) -> tuple[sp.Expr, int]:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(node, f"{_describe(node)} is not allowed here")
        segment = ast.get_source_segment(self.source, node) or repr(value)
        if "_" in segment:
            raise self.fail(node, f"number {segment[:16]!r}: write it without '_'")
        digits = sum(ch.isdigit() for ch in segment)
        if digits > MAX_DIGITS:
            raise self.fail(node, f"number {segment[:16]!r}: more than {MAX_DIGITS} digits")
        if isinstance(value, int):
            return sp.Integer(value), 0
        mantissa, _, exponent = segment.lower().partition("e")
        if exponent and abs(int(exponent)) > MAX_DIGITS:
            raise self.fail(node, f"number {segment!r}: exponent beyond ±{MAX_DIGITS}")
        # exact: the decimal text, never the binary float
        return sp.Rational(mantissa) * sp.Integer(10) ** int(exponent or 0), 0

    def _Name(self, node: ast.Name, depth: int) -> tuple[sp.Expr, int]:
        name = node.id
        if name in RESERVED:
            raise self.fail(node, f"{name!r} is a reserved name here"
                            + (" (a function: call it, e.g. sin(q))" if name in FUNCTIONS
                               else ""))
        self.names.setdefault(name, self.offset + node.col_offset)
        return sp.Symbol(name), 1

    def _UnaryOp(self, node: ast.UnaryOp, depth: int) -> tuple[sp.Expr, int]:
        operand, degree = self.walk(node.operand, depth)
        if isinstance(node.op, ast.USub):
            return -operand, degree
        if isinstance(node.op, ast.UAdd):
            return operand, degree
        raise self.fail(node, f"operator {type(node.op).__name__} is not allowed")

    def _BinOp(self, node: ast.BinOp, depth: int) -> tuple[sp.Expr, int]:
        if isinstance(node.op, ast.Pow):
            base, degree = self.walk(node.left, depth)
            n = self._exponent(node.right)
            if base.is_number:
                if base == 0 and n < 0:
                    raise self.fail(node, "division by zero (0 to a negative power)")
                size = abs(n) * _magnitude(base)
                if size > MAX_MAGNITUDE:
                    raise self.fail(node, f"a number of about 10^{size:.0f}: beyond "
                                    f"10^{MAX_MAGNITUDE}")
            return base**n, degree * abs(n)
        ops = {ast.Add: sp.Add, ast.Sub: lambda a, b: a - b, ast.Mult: sp.Mul,
               ast.Div: lambda a, b: a / b}
        op = ops.get(type(node.op))
        if op is None:
            raise self.fail(node, f"operator {type(node.op).__name__} is not allowed "
                            "(only + - * / **)")
        (left, dl), (right, dr) = self.walk(node.left, depth), self.walk(node.right, depth)
        if op is ops[ast.Div] and right == 0:
            raise self.fail(node, "division by zero")
        if isinstance(node.op, ast.Mult | ast.Div):
            result = op(left, right)
            if result.is_number and _magnitude(result) > MAX_MAGNITUDE:  # products too
                raise self.fail(node, f"a number beyond 10^{MAX_MAGNITUDE}")
            return result, dl + dr
        return op(left, right), max(dl, dr)

    def _exponent(self, node: ast.AST) -> int:
        sign, inner = 1, node
        if isinstance(inner, ast.UnaryOp) and isinstance(inner.op, ast.USub | ast.UAdd):
            sign = -1 if isinstance(inner.op, ast.USub) else 1
            inner = inner.operand
        if not (isinstance(inner, ast.Constant) and type(inner.value) is int):
            raise self.fail(node, "powers must be integers (write sqrt(...) for a square root)")
        if inner.value > MAX_POWER:
            raise self.fail(node, f"power {inner.value} is above the limit {MAX_POWER}")
        return sign * inner.value

    def _Call(self, node: ast.Call, depth: int) -> tuple[sp.Expr, int]:
        if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
            name = node.func.id if isinstance(node.func, ast.Name) else _describe(node.func)
            raise self.fail(node, f"function {name!r} is not allowed (allowed: "
                            f"{', '.join(sorted(FUNCTIONS))})")
        if node.keywords or len(node.args) != 1 or isinstance(node.args[0], ast.Starred):
            raise self.fail(node, f"{node.func.id}() takes exactly one argument")
        argument, degree = self.walk(node.args[0], depth)
        return FUNCTIONS[node.func.id](argument), degree

    def parse(self, source: str) -> sp.Expr:
        if not source.strip():
            raise InputError(f"{self.what} {self.text!r}, column {self.offset + 1}: empty side")
        self.offset += len(source) - len(source.lstrip())  # ast counts from the first token
        self.source = source.strip()
        try:
            tree = ast.parse(self.source, mode="eval")
        except SyntaxError as exc:
            # Python reports offset 0 for a text that ends too early: point at its end
            col = self.offset + (exc.offset - 1 if exc.offset else len(self.source))
            raise InputError(f"{self.what} {self.text!r}, column {col + 1}: does not parse "
                             f"({exc.msg})") from None
        except (RecursionError, MemoryError, ValueError):
            raise InputError(f"{self.what} {self.text!r}: too deeply nested to parse") from None
        return self.walk(tree)[0]


def _magnitude(x: sp.Expr) -> float:
    """``|log10 |x||`` of a nonzero number (0 for zero), from the digits of a rational."""
    if x == 0:
        return 0.0
    if x.is_Rational:
        return max(abs(x.p).bit_length(), abs(x.q).bit_length()) * math.log10(2)
    try:
        value = abs(complex(x))
    except (TypeError, OverflowError, ValueError):
        return math.inf
    return abs(math.log10(value)) if 0 < value < math.inf else math.inf


def _describe(node: ast.AST) -> str:
    kinds = {ast.Attribute: "attribute access", ast.Subscript: "indexing",
             ast.Lambda: "a lambda", ast.JoinedStr: "an f-string", ast.Compare: "a comparison",
             ast.ListComp: "a comprehension", ast.GeneratorExp: "a comprehension",
             ast.SetComp: "a comprehension", ast.DictComp: "a comprehension",
             ast.BoolOp: "a boolean operator", ast.IfExp: "a conditional",
             ast.NamedExpr: "an assignment", ast.Await: "await", ast.Starred: "unpacking"}
    if isinstance(node, ast.Constant):
        return f"constant {node.value!r}"[:40]
    return kinds.get(type(node), type(node).__name__)


def parse_expression(text: str, what: str = "expression") -> sp.Expr:
    """A formula without primes (a parameter value such as ``1/3``) through the walker."""
    if not isinstance(text, str):
        raise InputError(f"{what} {text!r}: not text")
    _check_characters(text, what)
    _check_names(text, text, what)
    if "'" in text or "=" in text:
        col = min(i for i in (text.find("'"), text.find("=")) if i >= 0)
        raise InputError(f"{what} {text!r}, column {col + 1}: {text[col]!r} is not allowed here")
    return _Walker(text, 0, what).parse(text)


def parse_sides(text: str, what: str = "equation"
                ) -> tuple[sp.Expr, sp.Expr, dict[str, int], dict[str, int]]:
    """The two sides of ``text`` through the walker, with ``q'`` and ``q''`` renamed ``q_`` and
    ``q__`` (the columns stay the user's); each primed name's highest derivative; every name's
    first column.  ``= 0`` may be left out."""
    if not isinstance(text, str):
        raise InputError(f"{what} {text!r}: not text")
    _check_characters(text, what)
    if text.count("=") > 1 or "==" in text:
        raise _fail(text, text.find("="), "one '=' at most (left side = right side)")
    orders: dict[str, int] = {}
    source = text
    for match in _PRIMED.finditer(text):
        name, primes = match.groups()
        orders[name] = max(orders.get(name, 0), len(primes))
        source = source[: match.start(2)] + "_" * len(primes) + source[match.end(2):]
    stray = source.find("'")
    if stray >= 0:
        raise _fail(text, stray, "a ' that is no prime after a name (quotes and strings are "
                    "not allowed; the derivatives are written q' and q'')")
    _check_names(text, text.replace("'", " "), what)
    left, _, right = source.partition("=")
    walker = _Walker(text, 0, what)
    lhs = walker.parse(left)
    names = dict(walker.names)
    rhs = sp.Integer(0)
    if "=" in source:
        right_walker = _Walker(text, len(left) + 1, what)
        rhs = right_walker.parse(right)
        for name, col in right_walker.names.items():
            names.setdefault(name, col)
    for name in orders:
        if name in (TIME, SMALL) or name in RESERVED:
            raise InputError(f"{what} {text!r}: {name!r} cannot be a coordinate")
    return lhs, rhs, orders, names


def derivative_symbols(coordinate: str) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol]:
    """``q``, ``q'``, ``q''`` of a coordinate's name."""
    return tuple(sp.Symbol(coordinate + "'" * k) for k in range(3))


def renamed(expr: sp.Expr, coordinates: Sequence[str]) -> sp.Expr:
    """``q_``, ``q__`` (as :func:`parse_sides` leaves them) back to ``q'``, ``q''``."""
    return expr.xreplace({sp.Symbol(c + "_" * k): derivative_symbols(c)[k]
                          for c in coordinates for k in range(3)})


def parse_equation(text: str) -> Equation:
    """Parse an equation of motion (see the module docstring); ``= 0`` may be left out."""
    lhs, rhs, orders, names = parse_sides(text)
    if len(orders) != 1:
        if not orders:
            raise InputError(f"equation {text!r}: no coordinate — write its acceleration with "
                             "primes, e.g. q''")
        raise InputError(f"equation {text!r}: primes on {', '.join(sorted(orders))}; "
                         "one coordinate only (a system: one equation per coordinate, "
                         "separated by ';')")
    (coordinate, top), = orders.items()
    if top != 2:
        raise InputError(f"equation {text!r}: the highest derivative is {coordinate}"
                         f"{chr(39) * top}; an oscillator's equation is of second order")
    derivatives = derivative_symbols(coordinate)
    others = sorted(n for n in names if n.rstrip("_") != coordinate and n not in (TIME, SMALL))
    small = sp.Symbol(SMALL) if SMALL in names else None
    return Equation(
        text=text,
        expression=renamed(lhs - rhs, [coordinate]),
        derivatives=derivatives,
        time=sp.Symbol(TIME),
        small=small,
        parameters=tuple(sp.Symbol(n) for n in others),
        lhs=renamed(lhs, [coordinate]),
        rhs=renamed(rhs, [coordinate]),
    )
