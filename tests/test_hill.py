"""Mathieu's characteristic values as exact series: DLMF 28.6.1–28.6.13 where they are printed,
and at any order against the eigenvalues of the truncated Hill matrix (mpmath, 40 digits)."""

from __future__ import annotations

import json
from fractions import Fraction as F

import mpmath as mp
import pytest
from commands import run_forked
from lindstedt.cli import main
from lindstedt.derive.hill import mathieu_series
from lindstedt.errors import InputError

DLMF = {  # coefficients of q^0, q^1, … as far as DLMF 28.6.1–28.6.13 print them
    # (https://dlmf.nist.gov/28.6, §28.6(i); the same as Abramowitz & Stegun 20.2.25)
    ("a", 0): [0, 0, F(-1, 2), 0, F(7, 128), 0, F(-29, 2304), 0, F(68687, 18874368)],  # 28.6.1
    ("a", 1): [1, 1, F(-1, 8), F(-1, 64), F(-1, 1536), F(11, 36864), F(49, 589824),
               F(55, 9437184), F(-83, 35389440)],  # 28.6.2
    ("b", 1): [1, -1, F(-1, 8), F(1, 64), F(-1, 1536), F(-11, 36864), F(49, 589824),
               F(-55, 9437184), F(-83, 35389440)],  # 28.6.3
    ("a", 2): [4, 0, F(5, 12), 0, F(-763, 13824), 0, F(1002401, 79626240), 0,
               F(-1669068401, 458647142400)],  # 28.6.4
    ("b", 2): [4, 0, F(-1, 12), 0, F(5, 13824), 0, F(-289, 79626240), 0,
               F(21391, 458647142400)],  # 28.6.5
    ("a", 3): [9, 0, F(1, 16), F(1, 64), F(13, 20480), F(-5, 16384), F(-1961, 23592960),
               F(-609, 104857600)],  # 28.6.6
    ("b", 3): [9, 0, F(1, 16), F(-1, 64), F(13, 20480), F(5, 16384), F(-1961, 23592960),
               F(609, 104857600)],  # 28.6.7
    ("a", 4): [16, 0, F(1, 30), 0, F(433, 864000), 0, F(-5701, 2721600000)],  # 28.6.8
    ("b", 4): [16, 0, F(1, 30), 0, F(-317, 864000), 0, F(10049, 2721600000)],  # 28.6.9
    ("a", 5): [25, 0, F(1, 48), 0, F(11, 774144), F(1, 147456), F(37, 891813888)],  # 28.6.10
    ("b", 5): [25, 0, F(1, 48), 0, F(11, 774144), F(-1, 147456), F(37, 891813888)],  # 28.6.11
    ("a", 6): [36, 0, F(1, 70), 0, F(187, 43904000), 0,
               F(6743617, 92935987200000)],  # 28.6.12
    ("b", 6): [36, 0, F(1, 70), 0, F(187, 43904000), 0,
               F(-5861633, 92935987200000)],  # 28.6.13
}


def test_dlmf_covers_every_printed_value():
    """a_0 … a_6 and b_1 … b_6: the thirteen series DLMF §28.6(i) prints."""
    assert sorted(DLMF) == sorted([("a", m) for m in range(7)] + [("b", m) for m in range(1, 7)])


@pytest.mark.parametrize(("kind", "m"), sorted(DLMF))
def test_dlmf_series(kind, m):
    expected = DLMF[(kind, m)]
    assert mathieu_series(kind, m, len(expected) - 1) == expected


def hill_eigenvalue(kind: str, m: int, q: mp.mpf, size: int = 20) -> mp.mpf:
    """a_m(q) or b_m(q) as the eigenvalue of the truncated recurrence of the Fourier
    coefficients (DLMF 28.4): cos 2kz, cos (2k+1)z, sin (2k+1)z or sin (2k+2)z.  For q ≤ 0.4
    the coefficients fall like q^k/(k!)²: 20 harmonics leave ~1e-30, far below the 1e-20
    asked (60 gave the same 30 digits at 30 times the cost)."""
    start = {("a", 0): 0, ("a", 1): 1, ("b", 1): 1, ("b", 0): 2}[(kind, m % 2)]
    harmonics = [start + 2 * k for k in range(size)]
    M = mp.matrix(size, size)
    for i, n in enumerate(harmonics):
        M[i, i] = n * n
        if i + 1 < size:
            M[i, i + 1] = M[i + 1, i] = q
    if start == 0:  # y = A_0 + Σ A_2k cos 2kz: the coupling to A_0 is 2q (symmetrised: √2 q)
        M[0, 1] = M[1, 0] = mp.sqrt(2) * q
    elif start == 1:  # cos z · 2q cos 2z holds cos z again: ±q on the first diagonal
        M[0, 0] = 1 + (q if kind == "a" else -q)
    values = sorted(mp.re(v) for v in mp.eig(M)[0])
    return values[(m - start) // 2]


@pytest.mark.parametrize(("kind", "m"), [("a", m) for m in range(7)]
                         + [("b", m) for m in range(1, 7)])  # b_0 does not exist
def test_series_against_the_hill_matrix(kind, m):
    series = mathieu_series(kind, m, 40)
    with mp.workdps(40):
        for q in (mp.mpf("0.1"), mp.mpf("0.4")):
            value = sum(mp.mpf(c.numerator) / c.denominator * q**k for k, c in enumerate(series))
            assert abs(value - hill_eigenvalue(kind, m, q)) < mp.mpf(10) ** -20, (kind, m, q)


def test_the_contract_and_bad_input(capsys):
    assert main(["mathieu", "a", "--m", "0", "--order", "40", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"kind", "m", "variable", "series"} and data["variable"] == "q"
    assert data["series"][:5] == ["0/1", "0/1", "-1/2", "0/1", "7/128"]
    assert len(data["series"]) == 41
    with pytest.raises(InputError, match="b_0 does not exist"):
        mathieu_series("b", 0, 4)
    for args in (["mathieu", "b", "--m", "0"], ["mathieu", "c"], ["mathieu", "a", "--m", "x"],
                 ["mathieu", "a", "--order", "-1"]):
        done = run_forked(*args, check=False)
        assert done.returncode == 2 and done.stdout == "", args
        assert done.stderr.count("\n") == 1 and done.stderr.startswith("lindstedt: error:")


TABLE_28_6_1 = {  # ρ_n^(j), n = 0 or 1: j = 1 for a_2n, 2 for b_2n+2, 3 for a_2n+1 and b_2n+1
    ("a", 0): 1.4687686138, ("a", 2): 1.4687686138, ("b", 2): 6.9289547588,
    ("b", 4): 6.9289547588, ("a", 1): 3.7699574940, ("b", 1): 3.7699574940,
    ("a", 3): 3.7699574940,
}


@pytest.mark.parametrize(("kind", "m"), sorted(TABLE_28_6_1))
def test_radius_of_convergence_against_table_28_6_1(kind, m, capsys):
    """``mathieu --singularities`` at order 100: within 0.1 % of DLMF Table 28.6.1 (Meixner et
    al. 1980), read in q**2 where the series lives in q² (a_2n, b_2n); the reported spread
    covers the error against the table in that variable (for the complex pairs of a_1, b_1,
    a_3 too, whose fits over the last orders alone spread 1.1e-3 for an error of 1.8e-3)."""
    assert main(["mathieu", kind, "--m", str(m), "--order", "100", "--singularities",
                 "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)["singularities"]
    expected = TABLE_28_6_1[(kind, m)]
    assert row["variable"] == ("q**2" if m % 2 == 0 else "q")
    radius = row["radius"] ** 0.5 if row["variable"] == "q**2" else row["radius"]
    assert abs(radius / expected - 1) < 1e-3, (kind, m, radius)
    assert 0 < row["spread"] < 0.01 * row["radius"]
    assert abs(row["radius"] - (expected**2 if m % 2 == 0 else expected)) <= row["spread"]
    if row["method"].startswith("Domb–Sykes"):  # a real branch point: the fit in 1/n of
        # degree 3 lands within 2e-6
        assert abs(radius / expected - 1) < 2e-6
