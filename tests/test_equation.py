"""Equations as text: the parser (nothing in the text ever runs), the JSON contract of
``lindstedt series`` for named and typed oscillators, and where L–P refuses (exit 2).

References are written here by hand: SymPy expressions built from symbols, exact periods from
elliptic integrals (``reference.py``) and from ``q = A sin θ`` with plain fractions.
"""

from __future__ import annotations

import builtins
import contextlib
import json
import re
import time
from fractions import Fraction
from math import factorial

import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lindstedt.cli import main
from lindstedt.derive.equation import parse_equation, parse_expression
from lindstedt.errors import InputError
from reference import duffing_period, reciprocal

Q, QD, QDD = sp.symbols("q q' q''")
EPS, ALPHA, BETA, T = sp.symbols("eps alpha beta t")
RATIONAL = re.compile(r"-?\d+/\d+")


# --- the parser ---------------------------------------------------------------------------------

def test_parse_equation_parts():
    eq = parse_equation("q'' + q + eps*(beta*q**2 + alpha*q**3) = 0")
    assert sp.expand(eq.expression - (QDD + Q + EPS * (BETA * Q**2 + ALPHA * Q**3))) == 0
    assert eq.derivatives == (Q, QD, QDD) and eq.coordinate == Q
    assert eq.small == EPS and eq.time == T
    assert eq.parameters == (ALPHA, BETA)
    right = parse_equation("q'' = -q - eps*(beta*q**2 + alpha*q**3)")
    assert sp.expand(right.expression - eq.expression) == 0
    bare = parse_equation("theta''+sin(theta)")  # "= 0" may be left out
    th = sp.Symbol("theta")
    assert bare.expression == sp.Symbol("theta''") + sp.sin(th)
    assert bare.small is None and bare.parameters == ()


@pytest.mark.parametrize("text, value", [
    ("0.1", sp.Rational(1, 10)), ("1e-3", sp.Rational(1, 1000)), (".5", sp.Rational(1, 2)),
    ("2.50e2", sp.Integer(250)), ("1/3", sp.Rational(1, 3)), ("-0.3", sp.Rational(-3, 10)),
    ("3.3333333333333333", sp.Rational(33333333333333333, 10**16)), ("2**-3", sp.Rational(1, 8)),
    ("1E2", sp.Integer(100)), ("(1 + 2)*3/4", sp.Rational(9, 4)),
])
def test_numbers_are_exact_decimals(text, value):
    assert parse_expression(text) == value
    assert parse_expression(text).is_Rational


@pytest.mark.parametrize("text, column", [
    ("q'' + q + q.real = 0", 11),
    ("q'' + q + abs(q) = 0", 11),
    ("q'' + q + q**0.5 = 0", 14),
    ("q'' + q # c", 9),
    ("q'' + q + 'a' = 0", 11),
    ("q'' + q + lambda: q = 0", 17),
    ("q'' + q + lambda*q = 0", 11),
    ("q'' + q + sin = 0", 11),
    ("q'' + q + 1/0 = 0", 11),
])
def test_errors_name_their_column_on_one_line(text, column):
    with pytest.raises(InputError) as info:
        parse_equation(text)
    message = str(info.value)
    assert "\n" not in message
    assert f"column {column}" in message


class _Trap:
    """Any use of this object (attribute, call, item, arithmetic, truth) records it."""

    touched = False

    def __getattribute__(self, name):
        _Trap.touched = True
        return object.__getattribute__(self, name) if name.startswith("__") else self

    def _hit(self, *args, **kwargs):
        _Trap.touched = True
        return self

    __call__ = __getitem__ = __add__ = __radd__ = __mul__ = __rmul__ = __pow__ = _hit
    __neg__ = __sub__ = __rsub__ = __truediv__ = __rtruediv__ = __index__ = _hit

    def __bool__(self):
        _Trap.touched = True
        return True


@contextlib.contextmanager
def sentinels():
    """``trap`` and ``q`` as builtins whose every use is recorded; eval, exec and imports of
    os/subprocess/sys count as execution too."""
    executed = []
    saved = {n: getattr(builtins, n, None) for n in ("trap", "eval", "exec", "__import__")}
    real_import = builtins.__import__

    def spy(name, globals=None, *args, **kwargs):
        # code run from a text has no module of its own: no __name__ in its globals
        if name.split(".")[0] in {"os", "subprocess", "shutil", "socket"} and \
                not (isinstance(globals, dict) and "__name__" in globals):
            executed.append(f"import {name}")
        return real_import(name, globals, *args, **kwargs)

    builtins.trap = _Trap()
    builtins.eval = lambda *a, **k: executed.append("eval")
    builtins.exec = lambda *a, **k: executed.append("exec")
    builtins.__import__ = spy
    _Trap.touched = False
    try:
        yield executed
    finally:
        for name, value in saved.items():
            if value is None:
                delattr(builtins, name)
            else:
                setattr(builtins, name, value)
        if _Trap.touched:
            executed.append("trap")


DANGEROUS = [
    "__import__('os').system('true')", "__import__", "trap.x", "trap(q)", "trap.real(q)",
    "q.real", "q.__class__", "trap.__class__.__bases__", "q[0]", "trap[0]", "lambda: q",
    "lambda q: q", "f'{q}'", "[q for q in q]", "(q for q in q)", "{q for q in q}", "{q: q}",
    "(q := 1)", "9**9**9", "q**100000", "q**(2**64)", "q**0.5", "q**q", "q**(1/2)",
    "-" * 3000 + "q", "-" * 70 + "q", "+".join(["q"] * 1100), "\u03b8", "q\u00b2", "\u00e9",
    "q\u00a0", "\u200bq", "\uff51", "q # comment", "'q'", '"q"', "{q}", "q\\", "\\x41", "q;q",
    "q\nq", "q\tq", "q if q else q", "q < q", "q and q", "not q", "~q", "q % q", "q // q",
    "q @ q", "q | q", "q << q", "**q", "q,q", "...", "True", "None", "1j", "1_000", "eval(q)",
    "exec(q)", "open(q)", "abs(q)", "sin(q, q)", "sin()", "sin", "pi", "E", "I", "oo", "zoo",
    "nan", "_q", "q_", "a" * 40, "9" * 50, "1e999", "1e-999", "await q", "yield q", "`q`",
    "$q", "q!", "q?", "q\x00", "sin(*q)", "q(0)", "(q)(q)", "sin(q)(q)",
]
TEMPLATES = ["q'' + q + {} = 0", "q'' + q + eps*({})*q**3 = 0", "q'' + sin({}) = 0",
             "{} = q''", "q'' + q = {}", "q'' + q + eps*q**3 + {}"]


@pytest.mark.filterwarnings("ignore::SyntaxWarning")
@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.sampled_from(DANGEROUS), min_size=1, max_size=3),
       st.sampled_from([" + ", " * ", " - "]), st.sampled_from(TEMPLATES))
def test_dangerous_texts_raise_input_error_and_run_nothing(fragments, joiner, template):
    text = template.format(joiner.join(fragments))
    with sentinels() as executed:
        start = time.perf_counter()
        with pytest.raises(InputError) as info:
            parse_equation(text)
        elapsed = time.perf_counter() - start
    assert executed == []
    assert elapsed < 1.0
    assert "\n" not in str(info.value)


@pytest.mark.filterwarnings("ignore::SyntaxWarning")
@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.text(alphabet=st.sampled_from(list("qt'eps*+-/()=. 0123456789alphsincoxgqrE_")),
               max_size=40))
def test_any_text_parses_or_raises_input_error(text):
    with sentinels() as executed:
        start = time.perf_counter()
        try:
            parse_equation(text)
        except InputError as exc:
            assert "\n" not in str(exc)
        elapsed = time.perf_counter() - start
    assert executed == []
    assert elapsed < 1.0


def test_the_sentinels_see_execution():
    """The sentinels themselves: code run from a text is seen."""
    real_eval = builtins.eval
    with sentinels() as executed:
        real_eval("trap.real")
        real_eval("__import__('os')", {})
        builtins.eval("q")
    assert executed == ["import os", "eval", "trap"]


_COEFFICIENT = st.one_of(
    st.fractions(min_value=-50, max_value=50, max_denominator=40).filter(lambda f: f != 0),
    st.integers(min_value=-10**6, max_value=10**6).filter(lambda n: n != 0)
    .map(lambda n: Fraction(n, 1000)),
)
_TERM = st.tuples(_COEFFICIENT, st.integers(0, 7), st.sampled_from([0, 2, 4]),
                  st.booleans(), st.sampled_from(["", "alpha", "k1", "alpha*k1"]),
                  st.booleans(), st.booleans())


def _coefficient_text(c: Fraction, as_decimal: bool) -> str:
    if as_decimal and c.denominator in (1, 2, 4, 5, 8, 10, 20, 25, 40, 50, 100, 1000):
        return str(float(c)) if len(repr(float(c))) < 18 else f"({c.numerator}/{c.denominator})"
    return f"({c.numerator}/{c.denominator})"


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.sampled_from(["q", "x", "theta", "u1"]), st.lists(_TERM, min_size=1, max_size=6))
def test_polynomial_texts_round_trip(name, terms):
    """Random polynomial equations: the parsed expression is the one built from symbols."""
    q, v, a = sp.symbols(f"{name} {name}' {name}''")
    left, right = [f"{name}''"], []
    expected = a
    names = set()
    for c, power, vpower, small, params, decimal, on_right in terms:
        factors = [_coefficient_text(c, decimal)]
        value = sp.Rational(c.numerator, c.denominator)
        if small:
            factors.append("eps")
            value *= EPS
        if params:
            factors.append(params)
            names.update(params.split("*"))
            for p in params.split("*"):
                value *= sp.Symbol(p)
        if power:
            factors.append(f"{name}**{power}" if power > 1 else name)
            value *= q**power
        if vpower:
            factors.append(f"{name}'**{vpower}")
            value *= v**vpower
        text = "*".join(factors)
        if on_right:
            right.append(f"-{text}")
        else:
            left.append(text)
        expected += value
    equation = " + ".join(left) + " = " + (" ".join(right) if right else "0")
    eq = parse_equation(equation)
    assert sp.expand(eq.expression - expected) == 0, equation
    assert eq.parameters == tuple(sp.Symbol(n) for n in sorted(names))
    assert eq.small == (EPS if any(t[3] for t in terms) else None)
    assert eq.derivatives == (q, v, a)


def test_nested_powers_of_numbers_are_bounded():
    with pytest.raises(InputError):
        parse_equation("q'' + q*((((2**64)**64)**64)**64) = 0")


def test_nested_powers_of_the_coordinate_keep_the_power_limit():
    with pytest.raises(InputError):
        parse_equation("q'' + q + eps*(q**64)**64 = 0")


def test_zero_to_a_negative_power_is_division_by_zero():
    with pytest.raises(InputError):
        parse_equation("q'' + q + eps*0**-1*q**3 = 0")


# --- the JSON contract ------------------------------------------------------------------------

def run_json(capsys, *args):
    assert main(["series", *args, "--json"]) == 0
    out = capsys.readouterr().out
    return json.loads(out)


def _fraction(text: str) -> Fraction:
    assert RATIONAL.fullmatch(text), text
    return Fraction(text)


DUFFING_KEYS = {"model", "order", "variable", "omega", "period", "q", "convention", "radius"}
EQUATION_KEYS = DUFFING_KEYS | {"equation", "omega0", "units"}
DUFFING_Q = [{"1": "1/1"}, {"1": "-1/32", "3": "1/32"},
             {"1": "23/1024", "3": "-3/128", "5": "1/1024"}]


def test_duffing_json_contract(capsys):
    data = run_json(capsys, "duffing", "--order", "5")
    assert set(data) >= DUFFING_KEYS  # the contract's keys; fields may be added
    # softening side: V = u²/2 + x u⁴/4 has its saddle at V = −1/(4x); V(1) = 1/2 + x/4 equals it
    # at (x + 1)² = 0, so the orbits end at x = −1; no edge for x > 0
    assert float(data["orbit_limit"]["lower"]) == -1.0
    assert data["orbit_limit"]["upper"] == "inf"
    assert data["model"] == "duffing" and data["order"] == 5
    assert data["variable"] == "y = eps*A**2" and data["radius"] == "1"
    assert data["convention"] == "q(0) = A, q'(0) = 0, so q_j(0) = 0 for j >= 1"
    assert data["omega"][:4] == ["1/1", "3/8", "-21/256", "81/2048"]
    assert data["period"][:4] == ["1/1", "-3/8", "57/256", "-315/2048"]
    exact = duffing_period(5)
    assert [_fraction(c) for c in data["period"]] == exact
    assert [_fraction(c) for c in data["omega"]] == reciprocal(exact)
    assert data["q"][:3] == DUFFING_Q
    assert len(data["q"]) == 6
    for j, qj in enumerate(data["q"]):  # q(0) = A: the harmonics of q_j sum to 0 (1 for j = 0)
        assert sum(_fraction(c) for c in qj.values()) == (1 if j == 0 else 0)
        assert all(int(n) % 2 == 1 and int(n) <= 2 * j + 1 for n in qj)


def test_duffing_typed_as_an_equation(capsys):
    named = run_json(capsys, "duffing", "--order", "5")
    text = "q'' + q + eps*q**3 = 0"
    typed = run_json(capsys, text, "--order", "5")
    assert set(typed) >= EQUATION_KEYS
    assert typed["orbit_limit"] == named["orbit_limit"]
    for key in ("omega", "period", "q", "variable", "order", "convention"):
        assert typed[key] == named[key], key
    assert typed["equation"] == text and typed["omega0"] == "1"
    assert typed["model"] == "oscillator"
    renamed = run_json(capsys, text, "--order", "2", "--name", "spring")
    assert renamed["model"] == "spring"


def _quintic_period(order: int) -> list[Fraction]:
    """``q'' + q + εq⁵ = 0``: ``T/2π = ⟨(1 + x(1 + σ + σ²)/3)^(−1/2)⟩``, ``σ = sin²θ``,
    ``x = εA⁴``: ``τ_k = C(−1/2, k)⟨((1 + σ + σ²)/3)^k⟩``."""
    out = []
    power = [Fraction(1)]  # coefficients of ((1 + σ + σ²)/3)^k in σ
    binom = Fraction(1)
    for k in range(order + 1):
        mean = sum((c * Fraction(factorial(2 * m), 4**m * factorial(m) ** 2)
                    for m, c in enumerate(power)), Fraction(0))
        out.append(binom * mean)
        nxt = [Fraction(0)] * (len(power) + 2)
        for i, c in enumerate(power):
            for d in range(3):
                nxt[i + d] += c / 3
        power = nxt
        binom *= Fraction(-1, 2) - k
        binom /= k + 1
    return out


def test_quintic_json(capsys):
    data = run_json(capsys, "q'' + q + eps*q**5 = 0", "--order", "6")
    assert data["variable"] == "y = eps*A**4"
    assert [_fraction(c) for c in data["period"]] == _quintic_period(6)
    assert [_fraction(c) for c in data["omega"]] == reciprocal(_quintic_period(6))
    for qj in data["q"]:
        assert all(RATIONAL.fullmatch(c) for c in qj.values())
    named = run_json(capsys, "quintic", "--order", "6")
    assert named["period"] == data["period"] and named["model"] == "quintic"


def _polynomial(coefficient: dict) -> sp.Expr:
    """A JSON coefficient object back to SymPy: each key a monomial, each value ``"p/q"``."""
    total = sp.Integer(0)
    for key, value in coefficient.items():
        monomial = sp.sympify(key)
        assert monomial.is_Mul or monomial.is_Pow or monomial.is_Symbol or monomial == 1, key
        assert str(monomial) == key  # SymPy's str() spelling, as the contract says
        f = _fraction(value)
        assert f != 0
        total += sp.Rational(f.numerator, f.denominator) * monomial
    return total


def test_two_powers_json_maps_monomials_to_rationals(capsys):
    text = "q'' + q + eps*(alpha*q**2 + q**3) = 0"
    data = run_json(capsys, text, "--order", "4")
    assert data["variable"] == "eps"
    assert data["omega"][0] == {"1": "1/1"} and data["period"][0] == {"1": "1/1"}
    assert data["omega"][1] == {"A**2": "3/8"} and data["period"][1] == {"A**2": "-3/8"}
    assert data["omega"][2] == {"A**2*alpha**2": "-5/12", "A**3*alpha": "1/4",
                                "A**4": "-21/256"}
    assert data["period"][2] == {"A**2*alpha**2": "5/12", "A**3*alpha": "-1/4",
                                 "A**4": "57/256"}
    A, al = sp.symbols("A alpha")
    omega = [_polynomial(c) for c in data["omega"]]
    period = [_polynomial(c) for c in data["period"]]
    # ω·(T/2π) = 1 order by order
    for j in range(1, 5):
        assert sp.expand(sum(omega[i] * period[j - i] for i in range(j + 1))) == 0
    # α = 0 is Duffing; T depends on εαA and εA² only: ε^j A^n α^m has n + m = 2j
    duffing = duffing_period(4)
    for j, c in enumerate(period):
        assert sp.expand(c.subs(al, 0) - duffing[j].numerator * A ** (2 * j)
                         / duffing[j].denominator) == 0
        for monomial in sp.Poly(c, A, al).monoms():
            assert monomial[0] + monomial[1] == 2 * j
    for qj in data["q"]:
        for coefficient in qj.values():
            _polynomial(coefficient)
    alpha_given = run_json(capsys, text, "--order", "4", "--param", "alpha=1/3")
    assert alpha_given["variable"] == "eps"
    for field in ("omega", "period"):
        for symbolic, numeric in zip(data[field], alpha_given[field], strict=True):
            assert sp.expand(_polynomial(symbolic).subs(al, sp.Rational(1, 3))
                             - _polynomial(numeric)) == 0
    for symbolic, numeric in zip(data["q"], alpha_given["q"], strict=True):
        left = {n: sp.expand(_polynomial(c).subs(al, sp.Rational(1, 3)))
                for n, c in symbolic.items()}
        assert {n: c for n, c in left.items() if c != 0} == \
               {n: _polynomial(c) for n, c in numeric.items()}


def test_models_lists_the_registry(capsys):
    assert main(["models", "--json"]) == 0
    listed = {e["name"]: e["equation"] for e in json.loads(capsys.readouterr().out)}
    assert listed["duffing"] == "q'' + q + eps*q**3 = 0"
    assert listed["pendulum"] == "theta'' + sin(theta) = 0"
    for name, equation in listed.items():
        parse_equation(equation)  # every registered equation is one the parser takes
        assert re.fullmatch(r"[a-z_]+", name)


# --- where L–P does not apply ----------------------------------------------------------------

REFUSED = [
    (["q'' + q + eps*q' = 0"], "q'"),
    (["q'' - q + q**3 = 0"], "restore"),
    (["q'' + q + abs(q) = 0"], "abs"),
    (["q'' + q + sqrt(q) = 0"], "sqrt(q)"),
    (["q'' + q + eps*q**3 = cos(t)"], "driven"),
    (["q'' + q + eps*cos(t)*q = 0"], "parametric"),
    (["q'' + q + eps*alpha*q**3 = 0", "--param", "alpha=1", "--param", "alpha=2"], "twice"),
    (["q'' + q + eps*alpha*q**3 = 0", "--param", "beta=1"], "beta"),
    (["q'' + q + eps*alpha*q**3 = 0", "--param", "alpha=beta"], "rational"),
    (["duffing", "--param", "alpha=1"], "parameters"),
    (["nosuchmodel"], "nosuchmodel"),
    (["q'' + q + eps*q**3 + q**5 = 0"], "eps"),
    (["q'' + alpha*q + eps*q**3 = 0"], "alpha"),
    (["q''' + q = 0"], "second order"),
    (["q'' + q = 0"], "linear"),
]


@pytest.mark.parametrize("args, needle", REFUSED)
def test_refused_with_one_line_and_exit_2(args, needle, capsys, tmp_path):
    assert main(["series", *args, "--order", "3"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("lindstedt: error: ")
    assert needle in lines[0]
    out = tmp_path / "never"
    assert main(["generate", *args, "--order", "3", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.splitlines()) == 1
    assert not out.exists()


def test_generate_refusal_leaves_an_existing_folder_empty(capsys, tmp_path):
    assert main(["generate", "q'' + q + eps*q' = 0", "--order", "3", "--out",
                 str(tmp_path)]) == 2
    capsys.readouterr()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("text", [
    pytest.param("q'' + q + q**3/alpha = 0", id="parameter-in-a-denominator"),
    pytest.param("q'' + q + sin(alpha)*q**3 = 0", id="function-of-a-parameter"),
    pytest.param("q'' + q + sin(1)*q**3 = 0", id="irrational-coefficient"),
    pytest.param("q'' + q + sqrt(2)*eps*q**3 = 0", id="sqrt-coefficient"),
    pytest.param("q'' + exp(1)*q + q**3 = 0", id="irrational-frequency"),
    pytest.param("q'' + q + q**3/eps = 0", id="eps-in-a-denominator"),
    pytest.param("q'' + q + exp(eps)*q**3 = 0", id="function-of-eps"),
])
def test_coefficients_outside_the_ring_are_refused(text, capsys):
    assert main(["series", text, "--order", "3"]) == 2
    assert len(capsys.readouterr().err.splitlines()) == 1


def test_a_text_that_ends_too_early_is_pointed_at_its_end():
    """Python reports no column for an unfinished expression: the error names the end."""
    with pytest.raises(InputError, match=r"column 10: does not parse"):
        parse_equation("q'' + q +")
