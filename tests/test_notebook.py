"""Notebook display: the example notebook runs, stays committed without outputs, and the
``_repr_latex_`` / ``_repr_html_`` of the results are exact and escaped."""

from __future__ import annotations

from fractions import Fraction
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from lindstedt.analysis.driven import (
    Drive,
    amplitudes,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
)
from lindstedt.choose import Choice, DrivenChoice, SolutionChoice, choose_period
from lindstedt.derive.lindstedt import derive, order_equation
from lindstedt.derive.models import duffing, pendulum
from lindstedt.display import html_table
from lindstedt.numerics.shooting import shoot
from reference import duffing_period, pendulum_period, reciprocal

NOTEBOOK = Path(__file__).resolve().parent.parent / "docs" / "example.ipynb"


def _frac(c: Fraction) -> str:
    """SymPy's LaTeX of a rational, written out independently: ``- \\frac{21}{256}``."""
    sign = "- " if c < 0 else ""
    c = abs(c)
    return f"{sign}\\frac{{{c.numerator}}}{{{c.denominator}}}" if c.denominator != 1 else \
        f"{sign}{c.numerator}"


class _Rows(HTMLParser):
    """The text of every cell of every ``<tr>`` (entities decoded), and the caption."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.rows: list[list[str]] = []
        self.caption, self._cell, self._in_caption = "", None, False

    def handle_starttag(self, tag: str, attrs: list) -> None:
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = ""
        elif tag == "caption":
            self._in_caption = True

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th"):
            self.rows[-1].append(self._cell)
            self._cell = None
        elif tag == "caption":
            self._in_caption = False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell += data
        elif self._in_caption:
            self.caption += data


def _parse(html_text: str) -> _Rows:
    p = _Rows()
    p.feed(html_text)
    return p


# --- the notebook ------------------------------------------------------------------------------

def test_example_notebook_is_committed_without_outputs():
    nbformat = pytest.importorskip("nbformat")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code
    for c in code:
        assert c.execution_count is None and c.outputs == [], c.source[:60]
    assert nb.metadata["kernelspec"]["name"] == "python3"
    assert not any("generator" in line.split() for c in code for line in c.source.splitlines()
                   if line.startswith(("import", "from"))), "the notebook imports lindstedt.*"


def test_example_notebook_runs_without_errors(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=120, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # raises CellExecutionError on the first failing cell
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    mimes = {m for o in outputs for m in o.get("data", {})}
    assert {"text/latex", "text/html", "image/png"} <= mimes
    assert list(tmp_path.iterdir()) == [], "the notebook writes no files"


# --- LaTeX of the derivation ---------------------------------------------------------------------

def test_series_latex_holds_the_exact_coefficients_of_the_elliptic_period():
    """ω₁ = 3/8, ω₂ = −21/256 and T/2π = 1 − 3x/8 + 57x²/256 − … , from K(m) (reference)."""
    text = derive(duffing(), 4)._repr_latex_()
    tau = duffing_period(4)
    omega = reciprocal(tau)
    assert omega[1:3] == [Fraction(3, 8), Fraction(-21, 256)]
    assert r"\omega &= 1 + \frac{3}{8} y - \frac{21}{256} y^{2}" in text
    for j in range(1, 5):
        power = "y" if j == 1 else f"y^{{{j}}}"
        assert f"{_frac(omega[j])} {power}" in text
        assert f"{_frac(tau[j])} {power}" in text
    assert r"q_{1}(s) &= - \frac{1}{32} \cos s + \frac{1}{32} \cos 3s" in text  # notes' q₁
    assert text.startswith("$$") and text.endswith("$$") and "O(y^{5})" in text


def test_series_latex_pendulum_coefficients():
    text = derive(pendulum(3), 3)._repr_latex_()
    tau = pendulum_period(3)
    for j in range(1, 4):
        assert _frac(tau[j]) in text
    assert r"y = \theta_{0}^{2}" in text


def test_series_latex_shows_the_first_orders_and_counts_the_rest():
    text = derive(duffing(), 30)._repr_latex_()
    assert "26 more orders" in text and "O(y^{31})" in text and r"\cdots" in text
    assert "q_{4}(s)" in text and "q_{5}(s)" not in text and "y^{5}" not in text
    assert len(text) < 2000


def test_order_equation_latex():
    text = order_equation(derive(duffing(), 3), 2)._repr_latex_()
    assert r"\omega_{2} = - \frac{21 A^{4}}{256}" in text
    assert text.count(r"\\") == 3  # four aligned lines


# --- HTML of the choices -------------------------------------------------------------------------

def _chosen(html_text: str) -> list[list[str]]:
    rows = _parse(html_text).rows
    assert rows[0][-1] == "chosen"
    marks = [r for r in rows[1:] if r[-1] == "✔"]
    assert all(r[-1] in ("✔", "") for r in rows[1:])
    return marks


def test_choice_table_escapes_method_names_and_marks_one_row():
    name = "a<b&c"
    c = Choice(name, 2, 1e-9, 3.5, 11, (("exact", 0, 0.0, 50.0), (name, 2, 1e-9, 3.5),
                                         ("<script>", 1, 1e-3, 1.0)))
    text = c._repr_html_()
    assert "a&lt;b&amp;c" in text and "&lt;script&gt;" in text
    assert "<script>" not in text and "a<b" not in text
    assert _chosen(text) == [[name, "2", "1.0e-09", "3.5", "✔"]]


def test_choice_tables_of_every_record_mark_exactly_the_chosen_method():
    sol = SolutionChoice("fourier", 5, 1e-10, 9.0, 100, (("lindstedt", 12, 1e-10, 9.5),
                                                         ("fourier", 5, 1e-10, 9.0)))
    assert [r[0] for r in _chosen(sol._repr_html_())] == ["fourier"]
    truth = None  # the table does not read it
    driven = DrivenChoice("amplitudes", "mu_expansion", 3, 1e-5, 20.0, 1,
                          (("harmonic_balance, emitted", 3, 1e-7, 90.0),
                           ("mu_expansion, emitted", 3, 1e-5, 20.0)), truth)
    marks = _chosen(driven._repr_html_())
    assert [r[0] for r in marks] == ["mu_expansion, emitted"]
    assert "choose_driven: amplitudes" in _parse(driven._repr_html_()).caption


def test_choose_period_table_marks_its_choice():
    c = choose_period(1e-6, 0.0, 0.3)
    marks = _chosen(c._repr_html_())
    assert len(marks) == 1 and marks[0][:2] == [c.method, str(c.order)]
    assert len(_parse(c._repr_html_()).rows) == 1 + len(c.considered)


def test_html_table_escapes_every_text():
    text = html_table("<caption&>", ["<h>"], [["<v>"]], note="<n>")
    assert "<caption&>" not in text and "<h>" not in text and "<v>" not in text
    assert "&lt;caption&amp;&gt;" in text and "&lt;n&gt;" in text


# --- HTML of the driven results ------------------------------------------------------------------

def test_driven_tables_at_the_notes_parameters():
    """μ-expansion order 6, balance N = 8 and shooting agree on A₁ = 2.355554 (README)."""
    d = Drive(0.1, 1.0, 1.0)
    (branch,) = first_order_branches(d)
    rows = _parse(branch._repr_html_()).rows
    assert rows == [["A₁", "δ₀"], ["2.37126", "0"]]  # notes: A₁ ≅ 2.371 at order 0
    mu = _parse(mu_expansion(d, branch, 6)._repr_html_())
    assert mu.rows[0] == ["order", "A1", "A3", "A5", "δ"]  # undamped: no B columns
    assert [r[1] for r in mu.rows[1:4]] == ["2.37126", "2.35737", "2.35575"]  # notes' orders
    assert mu.rows[-1][:2] == ["6", "2.35555"]
    hb = harmonic_balance(d, branch, 8)
    hb_rows = _parse(hb._repr_html_()).rows
    assert hb_rows[1] == ["1", "2.35555", "0"] and len(hb_rows) == 9
    A, _ = amplitudes(hb.coefficients, 0.0, 15)
    orbit = shoot(0.1, 1.0, 1.0, 0.0, np.array([sum(A.values()), 0.0]))
    text = orbit._repr_html_()
    assert _parse(text).rows[1][:2] == ["1", "2.35555"] and "stable" in text


def test_tables_truncate_long_results():
    d = Drive(0.1, 1.0, 1.0)
    branch = first_order_branches(d)[0]
    mu = _parse(mu_expansion(d, branch, 12)._repr_html_())
    assert [r[0] for r in mu.rows[1:]] == [str(j) for j in range(5, 13)]  # the last 8 orders
    hb = harmonic_balance(d, branch, 12)._repr_html_()
    assert "… and 4 more harmonics" in hb and len(_parse(hb).rows) == 9


def test_damped_mu_expansion_shows_sine_coefficients():
    d = Drive(0.1, 0.3, 1.2, 20.0)
    mu = _parse(mu_expansion(d, first_order_branches(d)[0], 3)._repr_html_())
    assert mu.rows[0] == ["order", "A1", "A3", "A5", "B1", "B3", "B5", "δ"]


def test_the_notebook_extra_brings_what_the_notebook_imports():
    """`pip install ".[notebook]"` is all the notebook needs: every module it imports is the
    package's, a dependency's, or the extra's (IPython comes with ipykernel)."""
    import ast
    import tomllib

    nbformat = pytest.importorskip("nbformat")
    project = tomllib.loads((NOTEBOOK.parent.parent / "pyproject.toml").read_text())["project"]
    extra = project["optional-dependencies"]["notebook"]
    assert any(r.startswith("jupyterlab") for r in extra)
    assert any(r.startswith("ipykernel") for r in extra)
    provided = {"lindstedt", "IPython", "sys", "tempfile", "pathlib", "mine"} | {
        r.split(">")[0].split("[")[0].split("<")[0].replace("python-", "") for r in
        project["dependencies"]}
    nb = nbformat.read(NOTEBOOK, as_version=4)
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        for node in ast.walk(ast.parse(cell.source)):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module] if isinstance(node, ast.ImportFrom) else [])
            for name in names:
                top = name.split(".")[0]
                assert top in provided, (name, sorted(provided))  # mine: the module it writes
