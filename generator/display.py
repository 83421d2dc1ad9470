"""Rich display in Jupyter: the shared pieces of the ``_repr_html_`` / ``_repr_latex_`` methods.

A leaf module like :mod:`errors` (it imports no other module of the package), so every stage
may use it.  HTML text is always escaped; LaTeX numbers come from SymPy's own printer (the
project's :func:`printers.latex_rational` belongs to a later stage).
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence

import sympy as sp

SHOWN_ORDERS = 4
# NOTE: a notebook repr shows orders 0..4 of a series and says how many more there are; the
# coefficients grow long quickly (order 40 of Duffing has 40-digit rationals).
SHOWN_ROWS = 8
# NOTE: table rows shown before "… n more" (harmonics, μ-orders).


def cell(value: object) -> str:
    """One table cell as text: floats to 6 significant digits, None as an empty cell."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value + 0.0:.6g}"  # -0.0 shows as 0
    return str(value)


def html_table(caption: str, headers: Sequence[str], rows: Iterable[Sequence[object]],
               marked: int | None = None, note: str = "") -> str:
    """A small HTML table; every text escaped.  ``marked``: the index of the row to mark as
    chosen (bold, with a ✔ in a last column); ``note``: a line below the table."""
    esc = html.escape
    head = "".join(f"<th>{esc(h)}</th>" for h in headers)
    if marked is not None:
        head += "<th>chosen</th>"
    body = []
    for i, row in enumerate(rows):
        cells = "".join(f"<td>{esc(cell(v))}</td>" for v in row)
        if marked is not None:
            cells += "<td>✔</td>" if i == marked else "<td></td>"
        style = ' style="font-weight:bold"' if i == marked else ""
        body.append(f"<tr{style}>{cells}</tr>")
    foot = f"<p>{esc(note)}</p>" if note else ""
    return (f"<div><table><caption>{esc(caption)}</caption><thead><tr>{head}</tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>{foot}</div>")


def more(total: int, shown: int, what: str = "orders") -> str:
    """``"… and 36 more orders"`` when ``shown < total``, else ``""``."""
    return f"… and {total - shown} more {what}" if total > shown else ""


def latex_aligned(lines: Iterable[str]) -> str:
    """Display math: one ``aligned`` block, lines already holding their ``&``."""
    return "$$\\begin{aligned}" + " \\\\ ".join(lines) + "\\end{aligned}$$"


def latex_text(text: str) -> str:
    """Plain text inside math, its LaTeX specials escaped."""
    for a, b in (("\\", r"\textbackslash{}"), ("{", r"\{"), ("}", r"\}"), ("_", r"\_"),
                 ("%", r"\%"), ("&", r"\&"), ("#", r"\#"), ("$", r"\$"), ("^", r"\^{}")):
        text = text.replace(a, b)
    return f"\\text{{{text}}}"


def latex_sum(terms: Iterable[tuple[sp.Expr, str]]) -> str:
    """``Σ c · factor`` with each coefficient printed exactly by SymPy (``\\frac{3}{8}``);
    a symbolic coefficient gets parentheses, a unit one is dropped before its factor."""
    out = []
    for c, factor in terms:
        c = sp.sympify(c)
        if c == 0:
            continue
        if c.is_Rational:
            sign = "-" if c < 0 else "+"
            mag = abs(c)
            body = "" if mag == 1 and factor else sp.latex(mag)
        elif not c.is_Add:  # one symbolic term: its own sign, no parentheses
            sign = "-" if c.could_extract_minus_sign() else "+"
            body = sp.latex(-c if sign == "-" else c)
        else:
            sign, body = "+", f"\\left({sp.latex(c)}\\right)"
        body = f"{body} {factor}".strip()
        out.append(f"{sign} {body}")
    if not out:
        return "0"
    text = " ".join(out)
    return text[2:] if text.startswith("+ ") else text


def harmonics_table(caption: str, A: dict[int, float], B: dict[int, float],
                    note: str = "") -> str:
    """``A_n``, ``B_n`` of ``q = Σ A_n cos nΩt + B_n sin nΩt`` by harmonic, the first rows
    (``Ω`` the orbit's fundamental: ``ω``, or ``ω/p`` for an orbit of p drive periods)."""
    ns = sorted(A)
    # below the rounding of the largest entry (a sine part that vanishes by symmetry but
    # carries the balance's 1e-17): 0
    floor = 1e-14 * max((abs(v) for v in (*A.values(), *B.values())), default=0.0)

    def shown(v: float | None) -> float | None:
        return None if v is None else (0.0 if abs(v) <= floor else v)

    rows = [(n, shown(A[n]), shown(B.get(n))) for n in ns[:SHOWN_ROWS]]
    note = "; ".join(t for t in (more(len(ns), SHOWN_ROWS, "harmonics"), note) if t)
    return html_table(caption, ("n", "A_n (cos)", "B_n (sin)"), rows, note=note)
