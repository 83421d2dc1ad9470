"""The LaTeX typesets: long integers break only between digit groups, and every kind of .tex
the tool writes compiles with pdflatex without running into the margin."""

import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp
from lindstedt.compiler import generate, generate_driven
from lindstedt.lower.printers import LATEX_LINE_DIGITS, latex_digits, latex_rational

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


# --- pdflatex -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def written(tmp_path_factory) -> dict[str, Path]:
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
    texs = {f"order-high/{p.name}": p for p in out.glob("*.tex")}
    texs.update({f"generated/{p.name}": p for p in GENERATED.glob("*.tex")})
    return texs


TEX_NAMES = [f"order-high/{m}_{kind}.tex" for m in ("duffing", "pendulum")
             for kind in ("tables", "derivation")] + ["order-high/driven_derivation.tex",
                                                      "order-high/driven_damped_derivation.tex",
                                                      "order-high/forced_slow_flow.tex"]


@pytest.mark.skipif(PDFLATEX is None, reason="pdflatex not installed (`make tex` installs it)")
@pytest.mark.parametrize("name", [*TEX_NAMES, *(f"generated/{p.name}"
                                               for p in sorted(GENERATED.glob("*.tex")))])
def test_tex_compiles_without_overfull_lines(written, name, tmp_path):
    tex = written[name]
    for _ in range(2):  # longtable settles its column widths on the second run
        run = subprocess.run(
            [PDFLATEX, "-interaction=nonstopmode", "-halt-on-error", str(tex)],
            cwd=tmp_path, stdin=subprocess.DEVNULL, capture_output=True, text=True,
            check=False, timeout=300,
        )
        assert run.returncode == 0, run.stdout[-3000:]
    log = (tmp_path / f"{tex.stem}.log").read_text(errors="replace")
    overfull = [line for line in log.splitlines() if line.startswith("Overfull \\hbox")]
    assert not overfull, overfull[:5]


@pytest.mark.parametrize("name", ["order-high/duffing_tables.tex",
                                  "order-high/pendulum_tables.tex",
                                  *(f"generated/{p.name}"
                                    for p in sorted(GENERATED.glob("*_tables.tex")))])
def test_no_number_in_a_table_is_split(written, name):
    """A table cell holds each number on one line (\\padmath shrinks a wide one to its
    column): no stacked digits, and every cell's digits are the exact coefficient's."""
    rows = [line for line in written[name].read_text().splitlines()
            if not line.startswith(("%", r"\newcommand"))]
    cells = [c for row in rows for c in re.findall(r"\\padmath\{(.*?)\}(?= &| \\\\)", row)]
    assert len(cells) > 20
    assert not any(LINES[0] in c for c in cells)
    long_ones = [c for c in cells if len(ungrouped(c)) > LATEX_LINE_DIGITS]
    if name.startswith("order-high/"):
        assert long_ones  # order 40: numbers far longer than a stacked line
    for cell in cells:
        assert re.fullmatch(r"-?(\\frac\{\d+\}\{\d+\}|\d+)", ungrouped(cell)), cell


def test_every_kind_of_tex_is_compiled(written):
    assert set(TEX_NAMES) == {n for n in written if n.startswith("order-high/")}
