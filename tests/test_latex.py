"""The LaTeX typesets: long integers break only between digit groups, series run several terms
to a line, the Fourier table is j × n with the exact coefficients, one notation (ε, y, the user's
coordinate, no raw input), and every kind of .tex the tool writes compiles with pdflatex without
running into the margin."""

import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp
from commands import van_der_pol_resummed
from lindstedt.cli.demo import LATEX_PASSES, RERUN
from lindstedt.compiler import generate, generate_driven
from lindstedt.derive.lindstedt import derive
from lindstedt.derive.models import model_by_name, series_model
from lindstedt.emit.render import derivation_context, tables_context
from lindstedt.lower.documents import lower_series_derivation, lower_tables
from lindstedt.lower.printers import (
    EXACT_WIDTH,
    LATEX_LINE_DIGITS,
    LINE_EM,
    latex_digits,
    latex_lines,
    latex_rational,
    latex_sum_items,
    latex_width,
)

GENERATED = Path(__file__).resolve().parents[1] / "generated"
PDFLATEX = shutil.which("pdflatex")
LINES = (r"\begin{array}{@{}r@{}}", r"\\", r"\end{array}")
# NOTE: how latex_digits stacks the lines of a long integer; with the thin space \, these
# are the only characters it adds to the digits.


def ungrouped(tex: str) -> str:
    """``tex`` with the group and line separators of :func:`latex_digits` removed."""
    return re.sub("|".join(map(re.escape, (*LINES, r"\,"))), "", tex)


# --- printers -------------------------------------------------------------------------------

def test_digit_groups_exact_strings():
    assert latex_digits(0) == "0"
    assert latex_digits(1234) == "1234"
    assert latex_digits(12345) == r"12\,345"
    assert latex_digits(57594037927936) == r"57\,594\,037\,927\,936"
    assert latex_digits(10**33) == (r"\begin{array}{@{}r@{}}1\,000\,000\,000\,000\,000"
                                    r"\\000\,000\,000\,000\,000\,000\end{array}")
    assert latex_rational(sp.Rational(-401225915283063, 72057594037927936)) == (
        r"-\frac{401\,225\,915\,283\,063}{72\,057\,594\,037\,927\,936}")
    assert latex_rational(sp.Integer(-72057)) == r"-72\,057"


def test_digit_groups_lose_no_digit():
    rng = random.Random(2024)
    numbers = [rng.randrange(10 ** (d - 1), 10**d) for d in range(1, 200) for _ in range(3)]
    for n in [*numbers, *(10**d for d in range(200))]:
        tex = latex_digits(n)
        assert ungrouped(tex) == str(n)
        lines = tex.removeprefix(LINES[0]).removesuffix(LINES[2]).split(LINES[1])
        groups = [line.split(r"\,") for line in lines]
        flat = [g for line in groups for g in line]
        if n >= 10**4:
            assert 1 <= len(flat[0]) <= 3 and all(len(g) == 3 for g in flat[1:]), tex
        assert all(len("".join(line)) <= LATEX_LINE_DIGITS for line in groups), tex
        assert max(map(len, groups)) - min(map(len, groups)) <= 1, tex  # balanced lines


def test_rationals_keep_every_digit():
    rng = random.Random(7)
    for _ in range(200):
        r = sp.Rational(rng.randrange(-10**90, 10**90), rng.randrange(1, 10**90))
        text = ungrouped(latex_rational(r))
        m = re.fullmatch(r"(-?)(?:\\frac\{(\d+)\}\{(\d+)\}|(\d+))", text)
        assert m, text
        sign, p, q, whole = m.groups()
        value = sp.Integer(whole) if whole else sp.Rational(int(p), int(q))
        assert (-value if sign else value) == r


def test_lines_hold_several_terms_and_a_short_sum_stays_on_one():
    assert latex_lines(["a", "+ b", "- c"]) == ["a + b - c"]
    assert latex_lines(["a", "+ b", "- c"], 3.0) == ["a + b", "- c"]
    terms = [rf"+ \frac{{{7**k}}}{{{2**k}}}\,y^{{{k}}}" for k in range(1, 13)]
    lines = latex_lines(["1", *terms], 30.0)
    assert 2 <= len(lines) <= 4  # 13 terms: never one a line
    assert " ".join(lines) == " ".join(["1", *terms])  # nothing lost, order kept
    assert all(latex_width(line) <= 30.0 for line in lines)


def test_a_term_wider_than_a_line_is_scaled_not_broken():
    wide = r"- \frac{" + "1" * 120 + r"}{7}\,y"
    assert latex_lines(["1", wide, "+ y"], 30.0) == ["1", r"- \fitmath{30em}{" + wide[2:] + "}",
                                                     "+ y"]


def test_common_factors_are_pulled_out_of_a_sum():
    A, eps, w, f = sp.symbols("A_1 eps omega f")
    expr = (-45 * A**7 * eps**3 + 60 * A**5 * eps**2 * w**2 - 16 * A**3 * eps) / (
        128 * w**4 * (9 * A**2 * eps - 4 * w**2 + 4))
    items = latex_sum_items(expr)
    assert items[0] == (r"\frac{\varepsilon A_{1}^{3}}{128 \omega^{4} \left(9 \varepsilon "
                        r"A_{1}^{2} - 4 \omega^{2} + 4\right)} \Bigl(")
    assert items[1:] == [r"- 45 \varepsilon^{2} A_{1}^{4}", r"+ 60 \varepsilon A_{1}^{2} "
                         r"\omega^{2}", r"- 16\Bigr)"]
    assert latex_sum_items(f / w**2 - A / 2) == [r"- \frac{A_{1}}{2} + \frac{f}{\omega^{2}}"]


# --- the documents --------------------------------------------------------------------------

DECIMAL = r"-?\d+\.\d+( \\cdot 10\^\{-?\d+\})?"
# NOTE: a table's long exact number, as its decimal (lower.printers.readable)


def tex_number(cell: str) -> sp.Rational | sp.Float:
    r"""The value of a table cell: exact ``-\frac{p}{q}`` or ``p`` (digits grouped), or a
    decimal ``-1.25 \cdot 10^{-3}`` (a Float of its 12 digits)."""
    text = ungrouped(cell)
    if re.fullmatch(DECIMAL, text):
        mantissa, _, power = text.partition(r" \cdot 10^{")
        return sp.Float(mantissa, 15) * sp.Integer(10) ** int(power.rstrip("}") or 0)
    m = re.fullmatch(r"(-?)(?:\\frac\{(\d+)\}\{(\d+)\}|(\d+))", text)
    assert m, cell
    sign, p, q, whole = m.groups()
    value = sp.Integer(whole) if whole else sp.Rational(int(p), int(q))
    return -value if sign else value


def fourier_table(tex: str) -> dict[tuple[int, int], sp.Rational | sp.Float]:
    """``{(j, n): coefficient}`` read from the Fourier table's blocks of a tables .tex."""
    section = tex[tex.index(r"\subsection*{Fourier coefficients"):]
    cells = {}
    for block in re.findall(r"\\begin\{longtable\}(.*?)\\end\{longtable\}", section, re.S):
        lines = [line.removesuffix(r" \\") for line in block.splitlines()]
        header = next(line for line in lines if line.startswith("$j$")).split(" & ")[1:]
        harmonics = [1 if h == r"$\cos s$" else int(re.fullmatch(r"\$\\cos (\d+)s\$", h)[1])
                     for h in header]
        for line in lines:
            if re.match(r"\d+ &", line):
                j, *row = line.split(" & ")
                assert len(row) == len(harmonics), line
                for n, cell in zip(harmonics, row, strict=True):
                    if cell:
                        cells[int(j), n] = tex_number(cell.removeprefix(r"\padmath{")[:-1])
    return cells


@pytest.mark.parametrize("model", ["duffing", "pendulum"])
def test_fourier_table_is_j_by_n_with_the_exact_coefficients(model):
    """The committed table: rows j = 0..K, columns n = 1, 3, …, 2K + 1, each entry the
    coefficient of cos ns in q_j of the series (Python API), exact where it is short and to
    12 significant digits where it is long; blocks fit the page."""
    tex = (GENERATED / f"{model}_tables.tex").read_text()
    order = int(re.search(r"order: (\d+)", tex)[1])
    solution = derive(model_by_name(model, order), order)
    exact = {(j, n): sp.Rational(str(c)) for j, qj in enumerate(solution.q) for n, c in qj.items()}
    table = fourier_table(tex)
    assert set(table) == set(exact)
    for key, value in table.items():
        if isinstance(value, sp.Float):
            assert abs(value / exact[key] - 1) <= 6e-12, (key, value, exact[key])
        else:
            assert value == exact[key], key
    assert any(isinstance(v, sp.Float) for v in table.values())  # order 12: long numbers
    assert {j for j, _ in exact} == set(range(order + 1))
    assert {n for _, n in exact} == set(range(1, 2 * order + 2, 2))
    if model == "duffing":  # q_1 = (cos 3s - cos s)/32: the notes' first order
        assert exact[1, 1] == sp.Rational(-1, 32) and exact[1, 3] == sp.Rational(1, 32)
    widths = [sum(float(w) for w in re.findall(r"p\{([\d.]+)em\}", spec))
              for spec in re.findall(r"\\begin\{longtable\}\{([^\n]*)\}\n", tex)]
    assert widths and max(widths) <= LINE_EM


def test_a_long_series_runs_several_terms_to_a_line():
    """T and ω of Duffing to order 12 (13 terms) take a few lines, order 2 one line."""
    ctx = tables_context(lower_tables(derive(model_by_name("duffing", 12), 12), 12))
    assert 2 <= len(ctx["period"]) <= 4 and 2 <= len(ctx["frequency"]) <= 4
    assert all(line.count("y^{") >= 2 for line in ctx["period"][:-1])
    sol = derive(model_by_name("duffing", 2), 2)
    short = tables_context(lower_tables(sol, 2))
    assert len(short["period"]) == 1 and len(short["frequency"]) == 1
    steps = derivation_context(lower_series_derivation(sol, 2))["orders"]
    assert len(steps[0]["solution"][0]["lines"]) == 1  # q_1: two terms, one line


# --- pdflatex -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def written(tmp_path_factory, run_folder) -> dict[str, Path]:
    """Every kind of .tex: high orders, so numbers run to 170 digits, and the committed ones."""
    out = tmp_path_factory.mktemp("tex")
    for model in ("duffing", "pendulum"):
        generate(model, 40, out)
    generate_driven(3, out)
    generate_driven(3, out, damped=True)
    from lindstedt.compiler import generate_slow_flow
    from lindstedt.derive.models import oscillator

    generate_slow_flow(oscillator("q'' + q = eps*(-k*q' - q**3 + F*cos(w*t))", name="forced"),
                       3, "cmd", out)
    generate_slow_flow(oscillator(VAN_DER_POL, name="van_der_pol"), 3, "cmd", out)
    # van der Pol's cycle at order 12, ω resummed from order 60: the module the suite makes once
    shutil.copy(van_der_pol_resummed(run_folder) / "van_der_pol_derivation.tex", out)
    generate(series_model(THETA, 6, {}, "swing"), 4, out)
    generate(series_model("helmholtz_duffing", 6), 4, out)
    from lindstedt.compiler import generate_nnm
    from lindstedt.derive.system import parse_system

    generate_nnm(parse_system(KERSCHEN), 2, 16, out, name="kerschen")
    texs = {f"order-high/{p.name}": p for p in out.glob("*.tex")}
    texs.update({f"generated/{p.name}": p for p in GENERATED.glob("*.tex")})
    return texs


VAN_DER_POL = "q'' + q = eps*(1 - q**2)*q'"
KERSCHEN = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
THETA = "theta'' + sin(theta) = 0"
TEX_NAMES = [f"order-high/{m}_{kind}.tex" for m in ("duffing", "pendulum", "swing",
                                                    "helmholtz_duffing")
             for kind in ("tables", "derivation")] + [
    f"order-high/{name}.tex" for name in ("driven_derivation", "driven_damped_derivation",
                                          "forced_slow_flow", "van_der_pol_slow_flow",
                                          "van_der_pol_derivation", "kerschen_tables",
                                          "kerschen_derivation")]


@pytest.mark.skipif(PDFLATEX is None, reason="pdflatex not installed (`make tex` installs it)")
@pytest.mark.parametrize("name", [*TEX_NAMES, *(f"generated/{p.name}"
                                               for p in sorted(GENERATED.glob("*.tex")))])
def test_tex_compiles_without_overfull_lines(written, name, tmp_path):
    tex = written[name]
    for _ in range(LATEX_PASSES):  # again while LaTeX asks, as the demo runs it (a longtable)
        run = subprocess.run(
            [PDFLATEX, "-interaction=nonstopmode", "-halt-on-error", str(tex)],
            cwd=tmp_path, stdin=subprocess.DEVNULL, capture_output=True, text=True,
            check=False, timeout=300,
        )
        assert run.returncode == 0, run.stdout[-3000:]
        log = (tmp_path / f"{tex.stem}.log").read_text(errors="replace")
        if not RERUN.search(log):
            break
    else:
        raise AssertionError(f"{name}: LaTeX still asks for another run after {LATEX_PASSES}")
    overfull = [line for line in log.splitlines() if line.startswith("Overfull \\hbox")]
    assert not overfull, overfull[:5]


@pytest.mark.parametrize("name", ["order-high/duffing_tables.tex",
                                  "order-high/pendulum_tables.tex",
                                  "order-high/kerschen_tables.tex",
                                  *(f"generated/{p.name}"
                                    for p in sorted(GENERATED.glob("*_tables.tex")))])
def test_no_number_in_a_table_is_split(written, name):
    """A table cell holds each number on one line (\\padmath shrinks a wide one to its
    column): no stacked digits; every cell exact, or a long number's decimal to at most 12
    significant digits."""
    rows = [line for line in written[name].read_text().splitlines()
            if not line.startswith(("%", r"\newcommand"))]
    cells = [c for row in rows for c in re.findall(r"\\padmath\{(.*?)\}(?= &| \\\\)", row)]
    assert len(cells) > 20
    assert not any(LINES[0] in c for c in cells)
    # NOTE: a long exact number is printed as a 12-digit decimal (the exact forms are in
    # --json and the module): short ones stay exact (p/q within EXACT_WIDTH characters).
    exact = r"-?(\\frac\{\d+\}\{\d+\}|\d+)"
    assert any(re.fullmatch(DECIMAL, ungrouped(c)) for c in cells)
    for cell in cells:
        assert re.fullmatch(f"{exact}|{DECIMAL}", ungrouped(cell)), cell
        if re.fullmatch(DECIMAL, ungrouped(cell)):  # 12 significant digits at most
            mantissa = ungrouped(cell).split(" ")[0].lstrip("-").replace(".", "")
            assert len(mantissa.lstrip("0")) <= 12, cell
        else:
            assert len(str(tex_number(cell))) <= EXACT_WIDTH, cell


def test_every_kind_of_tex_is_compiled(written):
    assert set(TEX_NAMES) == {n for n in written if n.startswith("order-high/")}


@pytest.mark.parametrize("name", [*TEX_NAMES, *(f"generated/{p.name}"
                                               for p in sorted(GENERATED.glob("*.tex")))])
def test_one_notation_and_no_raw_input(written, name):
    """ε is \\varepsilon, cos s never \\cos 1s, no breqn, and the equation is typeset: no
    input syntax (``**``, ``eps*``, a bare ``sin`` or ``theta``) outside the banner's comments."""
    body = [line for line in written[name].read_text().splitlines()
            if not line.startswith("%")]
    text = "\n".join(body)
    assert r"\epsilon" not in text and "breqn" not in text
    assert not re.search(r"\\(cos|sin)\s*\{?\s*1\s*[a-z\\]", text)
    assert not re.search(r"\*\*|eps\*|(?<!\\)(sin|cos|theta)|\\texttt", text)


def test_the_expansion_variable_is_y_and_headers_use_the_coordinate(written):
    duffing = written["order-high/duffing_tables.tex"].read_text()
    assert r"y = \varepsilon A^{2}" in duffing and "x = " not in duffing
    swing = written["order-high/swing_tables.tex"].read_text()
    assert r"$\theta(0) = A$" in swing and "q(0)" not in swing
    assert r"\ddot{\theta} + \sin\theta = 0" in swing
    cycle = written["order-high/van_der_pol_derivation.tex"].read_text()
    assert r"\ddot{q} + q = \varepsilon \dot{q} \left(1 - q^{2}\right)" in cycle


def test_normal_mode_tables_hold_the_exact_series(written):
    """The mode's tables: ω over √3 and the coordinates' coefficients as the series has them
    (x₁'s order-1 coefficients ∓25/4992, x₂'s order 0 −1), the equations as mathematics."""
    text = written["order-high/kerschen_tables.tex"].read_text()
    assert r"\omega_0 = \sqrt{3}" in text and "y = A^{2}" in text
    assert r"\frac{1}{32}\,y" in text  # ω = √3(1 + y/32 + …)
    assert r"\frac{25}{4992}" in text
    assert r"\ddot{x_{1}}" in text and "**" not in text.split("\\begin{document}")[1]
    from lindstedt.derive.nnm import normal_mode, radius
    from lindstedt.derive.system import parse_system

    found = radius(normal_mode(parse_system(KERSCHEN), 2, 24))  # as generate derives it
    assert f"its lower bound ${found.lower:.6g}$" in text and f"{found.estimate:.6g}" in text
