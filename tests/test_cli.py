"""The command line: the JSON contract, the table, and bad input (one line, exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys
from fractions import Fraction

import pytest
from reference import duffing_period, pendulum_period, reciprocal


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "lindstedt", *args], capture_output=True, text=True, check=False
    )


def test_series_duffing_order_40_contract():
    out = run("series", "duffing", "--order", "40", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert {"model", "order", "variable", "omega", "period", "q"} <= data.keys()
    assert data["model"] == "duffing" and data["order"] == 40
    assert data["variable"] == "x = eps*A**2"
    exact = duffing_period(40)
    assert [Fraction(c) for c in data["period"]] == exact
    assert [Fraction(c) for c in data["omega"]] == reciprocal(exact)
    assert all("/" in c for c in data["omega"])
    assert len(data["q"]) == 41
    assert data["q"][1] == {"1": "-1/32", "3": "1/32"}
    assert data["q"][2] == {"1": "23/1024", "3": "-3/128", "5": "1/1024"}


def test_series_pendulum_contract():
    data = json.loads(run("series", "pendulum", "--order", "12", "--json").stdout)
    assert data["variable"] == "theta0**2"
    assert [Fraction(c) for c in data["period"]] == pendulum_period(12)


def test_table_is_readable():
    out = run("series", "duffing", "--order", "2")
    assert out.returncode == 0
    assert "-21/256" in out.stdout and "57/256" in out.stdout


@pytest.mark.parametrize(
    "args,needle",
    [
        (["series", "duffing", "--order", "-3"], "order -3"),
        (["series", "duffing", "--order", "2.5"], "order '2.5'"),
        (["series", "nosuch"], "nosuch"),
        (["series", "duffing", "--order", "5000"], "--force"),
        (["series", "pendulum", "--order", "400"], "--force"),
    ],
)
def test_bad_input_one_line_exit_2(args, needle):
    out = run(*args)
    assert out.returncode == 2
    assert out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0]
    assert "Traceback" not in out.stderr
