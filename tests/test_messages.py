"""Messages a fuzz found misleading: a bound that says "≥ 0" where 0 is refused too, and a
range printed with its ends alike."""

from __future__ import annotations

import pytest
from commands import run
from lindstedt.cli import build_parser, main
from lindstedt.cli.common import interval

SYSTEM = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"


@pytest.mark.parametrize("argv", [
    ["nnm", SYSTEM, "--mode", "{}"],
    ["generate", SYSTEM, "--mode", "{}", "--out", "x"],
    ["choose", "backbone", SYSTEM, "--mode", "{}"],
    ["slowflow", "van_der_pol", "--order", "{}"],
    ["sweep", "response", "--workers", "{}"],
])
@pytest.mark.parametrize("value", ["0", "-1"])
def test_a_flag_that_refuses_zero_says_so(argv, value, capsys):
    """Modes are numbered from 1 and slowflow's order starts at 1: 0 and −1 are refused at the
    parse with "> 0", never with "≥ 0"."""
    with pytest.raises(SystemExit) as stop:
        build_parser().parse_args([a.format(value) for a in argv])
    err = capsys.readouterr().err.strip()
    assert stop.value.code == 2 and len(err.splitlines()) == 1, err
    assert f"{value}: must be > 0" in err and "≥ 0" not in err, err


def test_a_flag_that_takes_zero_still_says_at_least_zero(capsys):
    assert build_parser().parse_args(["series", "duffing", "--order", "0"]).order == 0
    with pytest.raises(SystemExit):
        build_parser().parse_args(["series", "duffing", "--order", "-1"])
    assert "-1: must be ≥ 0" in capsys.readouterr().err


@pytest.mark.parametrize("lo, hi, digits, shown", [
    (1.0, 1.0000001, 4, "[1, 1.0000001]"),
    (0.5, 2.25, 4, "[0.5, 2.25]"),
    (1.23456789, 1.23456799, 6, "[1.2345679, 1.234568]"),
    (1.0, 1.0000000000000002, 4, "[1, 1.0000000000000002]"),
])
def test_interval_tells_the_ends_apart(lo, hi, digits, shown):
    assert interval(lo, hi, digits) == shown
    left, right = shown[1:-1].split(", ")
    assert (float(left) < float(right)) == (lo < hi)


def test_response_prints_a_narrow_range_with_distinct_ends(capsys):
    assert main(["response", "q'' + q'/10 + q + q**3/10 = cos(w*t)/2", "--omega",
                 "1:1.0000001"]) == 0
    head = capsys.readouterr().out.splitlines()[0]
    assert head.endswith("w in [1, 1.0000001] (omega0 = 1)"), head



HUGE = "1" + "0" * 400


@pytest.mark.parametrize("argv", [["choose", "period", "--tol", "1e-6", "--range", f"0:{HUGE}"],
                                  ["response", "duffing", "--omega", HUGE],
                                  ["generate", "duffing", "--order", HUGE]])
def test_a_huge_number_is_named_by_its_ends_and_length(argv):
    """A 401-digit value (refused by argparse, or by the command itself): one line that names
    it by its ends and its length rather than echoing it whole; exit status 2."""
    done = run(*argv)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "1000000000…0000 (401 digits)" in done.stderr
    assert HUGE not in done.stderr and len(done.stderr) < 250, done.stderr
