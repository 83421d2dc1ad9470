"""Mathieu's equation ``y'' + (a − 2q cos 2z) y = 0``: its characteristic values a_m(q), b_m(q)
as exact power series in q (DLMF §28.6), by the L–P expansion about ``cos mz`` or ``sin mz``.

With ``y = cos mz + Σ_k q^k y_k(z)`` (``sin mz`` for b_m) and ``a = m² + Σ_k α_k q^k``, order k
reads ``y_k'' + m² y_k = 2 cos 2z · y_(k−1) − Σ_(i=1..k) α_i y_(k−i)``; with ``y_k`` free of
``cos mz`` the secular condition (no ``cos mz`` on the right) gives ``α_k`` as the ``cos mz``
coefficient of ``2 cos 2z · y_(k−1)``, and ``y_k`` follows harmonic by harmonic,
``c_n / (m² − n²)``.  ``2 cos 2z cos nz = cos(n+2)z + cos(n−2)z`` (and the same with sines,
``sin(−x) = −sin x``) is the whole algebra: exact rationals, no secular term left.
"""

from __future__ import annotations

from fractions import Fraction

from .errors import InputError
from .models import check_order

KINDS = ("a", "b")
MAX_M = 100
# NOTE: m indexes the tongue δ = m²/4 of ẍ + (δ + ε cos t)x = 0; far above any use.


def mathieu_series(kind: str, m: int, order: int) -> list[Fraction]:
    """``[c_0, c_1, …, c_K]`` with ``a_m(q)`` (kind "a", m ≥ 0) or ``b_m(q)`` (kind "b",
    m ≥ 1) ``= Σ c_k q^k``, DLMF's normalisation ``y'' + (a − 2q cos 2z) y = 0``."""
    if kind not in KINDS:
        raise InputError(f"kind {kind!r}: a (even solutions ce_m) or b (odd, se_m)")
    if isinstance(m, bool) or not isinstance(m, int) or not (0 if kind == "a" else 1) <= m \
            <= MAX_M:
        lowest = 0 if kind == "a" else 1
        raise InputError(f"--m {m!r}: an integer {lowest}..{MAX_M} for {kind}_m (b_0 does not "
                         "exist)" if kind == "b" else f"--m {m!r}: an integer 0..{MAX_M}")
    order = check_order(order)
    sign = 1 if kind == "a" else -1  # cos(−x) = cos x, sin(−x) = −sin x

    def times_2cos2z(y: dict[int, Fraction]) -> dict[int, Fraction]:
        out: dict[int, Fraction] = {}
        for n, c in y.items():
            for k, s in ((n + 2, 1), (abs(n - 2), sign if n < 2 else 1)):
                if kind == "b" and k == 0:
                    continue  # sin 0z = 0
                out[k] = out.get(k, Fraction(0)) + s * c
        return {n: c for n, c in out.items() if c}

    ys: list[dict[int, Fraction]] = [{m: Fraction(1)}]
    alphas = [Fraction(m * m)]
    for k in range(1, order + 1):
        rhs = times_2cos2z(ys[k - 1])
        alpha = rhs.get(m, Fraction(0))  # the secular condition (y_j free of cos mz, j ≥ 1)
        alphas.append(alpha)
        for i in range(1, k + 1):
            for n, c in ys[k - i].items():
                rhs[n] = rhs.get(n, Fraction(0)) - alphas[i] * c
        ys.append({n: c / (m * m - n * n) for n, c in rhs.items() if n != m and c})
    return alphas
