"""The command line: the JSON contract, the table, and bad input (one line, exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys
from fractions import Fraction

import pytest
from commands import run
from reference import duffing_period, pendulum_period, reciprocal


def test_series_duffing_order_40_contract():
    out = run("series", "duffing", "--order", "40", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert {"model", "order", "variable", "omega", "period", "q"} <= data.keys()
    assert data["model"] == "duffing" and data["order"] == 40
    assert data["variable"] == "y = eps*A**2"
    exact = duffing_period(40)
    assert [Fraction(c) for c in data["period"]] == exact
    assert [Fraction(c) for c in data["omega"]] == reciprocal(exact)
    assert all("/" in c for c in data["omega"])
    assert len(data["q"]) == 41
    assert data["q"][1] == {"1": "-1/32", "3": "1/32"}
    assert data["q"][2] == {"1": "23/1024", "3": "-3/128", "5": "1/1024"}


def test_series_pendulum_contract():
    data = json.loads(run("series", "pendulum", "--order", "12", "--json").stdout)
    assert data["variable"] == "y = theta0**2"
    assert [Fraction(c) for c in data["period"]] == pendulum_period(12)


def test_table_is_readable():
    out = run("series", "duffing", "--order", "2")
    assert out.returncode == 0
    assert "-21/256" in out.stdout and "57/256" in out.stdout


@pytest.mark.parametrize(
    "args,needle",
    [
        (["series", "duffing", "--order", "-3"], "--order: -3: must be ≥ 0"),
        (["series", "duffing", "--order", "2.5"], "--order: '2.5'"),
        (["series", "nosuch"], "nosuch"),
        (["series", "duffing", "--order", "5000"], "--allow-slow"),
        (["series", "pendulum", "--order", "400"], "--allow-slow"),
        (["generate", "duffing", "--out", ""], "--out ''"),
        (["driven", "--eps", "0.1", "--force", "1", "--omega", "nan"], "--omega: 'nan'"),
        (["driven", "--eps", "0.1", "--force", "1", "--omega", "1", "--harmonics", "0"],
         "--harmonics: 0"),
        (["choose", "period", "--tol", "-1e-8", "--range", "0:0.1"],
         "tol -1e-08: must be > 0"),
        (["mixing", "--eps", "0.1", "--Q", "10", "--drive", "0.3"], "F@W"),
        (["serie", "duffing"], "invalid choice: 'serie'; did you mean 'series'?"),
        (["respnse"], "did you mean 'response'?"),
        (["series", "duffing", "--ordr", "3"], "did you mean --order for --ordr?"),
        (["sweep", "stability", "--omega", "1", "--out", "x", "--workrs", "2"],
         "did you mean --workers for --workrs?"),
    ],
)
def test_bad_input_one_line_exit_2(args, needle):
    out = run(*args)
    assert out.returncode == 2
    assert out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0]
    assert "Traceback" not in out.stderr


@pytest.mark.parametrize("name", ["numpy", "numba", "scipy", "math", "sys", "json", "flint",
                                  "lindstedt"])
def test_name_that_shadows_a_module_is_refused(tmp_path, name):
    """``--name numpy`` would write numpy.py, which shadows NumPy for every script run from that
    folder: one line, exit 2, nothing written."""
    out = run("generate", "q'' + q + eps*q**2 = 0", "--name", name, "--order", "2",
              "--out", str(tmp_path / "gen"))
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.strip().splitlines() == [
        f"lindstedt: error: name {name!r}: a module of that name is importable (Python's own "
        "or installed); the written module would shadow it: choose another name"]
    assert not (tmp_path / "gen").exists()


@pytest.mark.parametrize("args,dropped", [
    (["mathieu", "a", "--m", "3", "--order", "20", "--json"], "--json"),
    (["mathieu", "a", "--m", "3", "--order", "20", "--singularities"], "--singularities"),
    (["mathieu", "b", "--m", "1", "--json", "--singularities"], "--json, --singularities"),
    (["tongues", "cos(t)", "--json"], "--json"),
])
def test_emit_refuses_printing_flags_beside_it(tmp_path, args, dropped):
    """``--out`` prints only the module's path: a printing flag beside it is refused in one
    line (exit 2) before anything is derived or written, in ``mathieu`` as in ``tongues``."""
    out = run(*args, "--out", str(tmp_path / "new"))
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.strip().splitlines() == [
        f"lindstedt: error: --out writes the module only: drop {dropped}"]
    assert not (tmp_path / "new").exists()


def test_negative_and_scientific_values_are_values_not_flags():
    """``--eps -1e-1`` and ``--drive -0.3@1.3`` are read as numbers (argparse alone calls them
    unknown flags); the result equals the one with the same value written plainly."""
    neg = run("subharmonic", "--eps", "-1e-1", "--force", "0.5", "--omega", "0.9", "--json")
    plain = run("subharmonic", "--eps=-0.1", "--force", "0.5", "--omega", "0.9", "--json")
    assert neg.returncode == 0, neg.stderr
    assert json.loads(neg.stdout) == json.loads(plain.stdout)
    assert json.loads(neg.stdout)["parameters"]["eps"] == -0.1


def test_force_in_series_is_the_old_spelling_of_allow_slow():
    out = run("series", "duffing", "--order", "2", "--force", "--json")
    assert out.returncode == 0
    assert "deprecated" in out.stderr and "--allow-slow" in out.stderr
    assert json.loads(out.stdout)["omega"][1] == "3/8"


def test_light_constants_match_the_stages():
    """The parser's choices are restated in cli (no SymPy at start-up): they must agree."""
    from lindstedt import choose
    from lindstedt.cli import common as cli
    from lindstedt.derive import models

    assert cli.FREE_MODELS == models.MODELS
    assert tuple(choose.SCENES) == cli.SCENE_NAMES
    assert cli.DRIVEN_QUANTITIES == choose.DRIVEN_QUANTITIES


def test_help_imports_no_heavy_stage():
    """``lindstedt --help`` and argument errors load neither SymPy, numba, SciPy nor
    matplotlib (the start-up target is 0.3 s; benchmarks/startup.py measures it)."""
    probe = ("import sys, lindstedt.cli as c\n"
             "try:\n    c.main(['series', '--help'])\nexcept SystemExit:\n    pass\n"
             "try:\n    c.main(['driven', '--eps', 'x'])\nexcept SystemExit:\n    pass\n"
             "heavy = {'sympy', 'numba', 'scipy', 'matplotlib', 'numpy'} & set(sys.modules)\n"
             "print(sorted(heavy))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_every_flag_has_help_and_states_its_default():
    import argparse

    from lindstedt.cli import build_parser

    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices
    for name, sub in commands.items():
        for action in sub._actions:
            if action.dest == "help" or action.help == argparse.SUPPRESS:  # an old spelling
                continue
            assert action.help, (name, action.option_strings)
            if action.option_strings and not action.required and action.default not in (
                    None, False) and action.nargs != 0:
                assert "default" in action.help, (name, action.option_strings)


def test_progress_bar_only_on_a_terminal_and_never_with_json(monkeypatch):
    import io

    from lindstedt.cli import common as cli

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    monkeypatch.setattr(cli, "PROGRESS_AFTER_SECONDS", 0.0)
    for stream, enabled, drawn in ((Terminal(), True, True), (Terminal(), False, False),
                                   (io.StringIO(), True, False)):
        monkeypatch.setattr(sys, "stderr", stream)
        bar = cli.ProgressBar("work", enabled)
        for done in range(1, 5):
            bar(done, 4)
        bar.close()
        text = stream.getvalue()
        assert ("[" + "#" * 30 + "] 4/4" in text) == drawn
        assert text.endswith("\r\033[K") == drawn


OLD_SPELLINGS = {"--emit": "--out", "--store": "--out", "--x-min": "--range",
                 "--x-max": "--range", "--omega-min": "--omega", "--omega-max": "--omega",
                 "--omega-from": "--omega", "--omega-to": "--omega", "--points": "--omega",
                 "--damping": "--zeta", "--at": "--eps"}


def test_one_spelling_per_meaning_across_commands():
    """Every command's visible flags use one spelling per meaning: an output folder is --out, a
    frequency --omega (W, A:B or A:B:N), a damping ratio --zeta; the old spellings are hidden
    from --help (they keep working, with a note)."""
    import argparse

    from lindstedt.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name, parser in sub.choices.items():
        for action in parser._actions:
            visible = action.help is not argparse.SUPPRESS
            for flag in action.option_strings:
                if flag in OLD_SPELLINGS or (flag == "--force" and action.nargs == 0):
                    assert not visible, f"{name} {flag}: an old spelling shown in --help"
                if visible and action.metavar in ("DIR", "PATH"):
                    assert flag == "--out", f"{name} {flag}: an output folder is --out"
                if visible and "ω" in (action.help or "") and "frequency" in action.help and (
                        flag.startswith("--omega")):
                    assert flag == "--omega", f"{name} {flag}"


@pytest.mark.parametrize("old, new", [
    (["tongues", "cos(t)", "--order", "4", "--at", "0.1", "--damping", "0.01", "--json"],
     ["tongues", "cos(t)", "--order", "4", "--eps", "0.1", "--zeta", "0.01", "--json"]),
    (["parametric", "--eps", "0.2", "--omega-from", "0.95", "--omega-to", "1.05", "--points",
      "3", "--harmonics", "2", "--json"],
     ["parametric", "--eps", "0.2", "--omega", "0.95:1.05:3", "--harmonics", "2", "--json"]),
])
def test_old_spellings_still_work_with_a_one_line_note(old, new):
    """An old spelling gives the same output as the new one, and one note line per old flag
    on stderr naming the new spelling."""
    before, after = run(*old), run(*new)
    assert before.returncode == after.returncode == 0, before.stderr
    assert before.stdout == after.stdout and after.stderr == ""
    notes = before.stderr.strip().splitlines()
    olds = [a for a in old if a in OLD_SPELLINGS]
    assert len(notes) == len(olds)
    for flag, note in zip(olds, notes, strict=True):
        head = f"lindstedt: note: {flag} is deprecated and goes in the next release; use "
        assert note.startswith(head + OLD_SPELLINGS[flag]), note


@pytest.mark.parametrize("args, says", [
    (["parametric", "--eps", "0.2", "--omega", "1"], "--omega: '1': write A:B or A:B:N"),
    (["parametric", "--eps", "0.2", "--omega", "1:2:3:4"], "write A:B or A:B:N"),
    (["parametric", "--eps", "0.2", "--omega", "0.9:1.1:1"], "must be in 2..401"),
    (["parametric", "--eps", "0.2", "--omega", "0.9:abc"], "'abc': not a number"),
    (["parametric", "--eps", "0.2"], "required: --omega A:B[:N]"),
    (["driven", "--eps", "0.1", "--force", "0.3", "--omega", "1:2"], "write W"),
    (["response", "q'' + q'/10 + q + q**3/10 = cos(w*t)/2", "--omega", "1"], "write A:B"),
    (["choose", "period", "--tol", "1e-3"], "choose period needs --range A:B"),
    (["sweep", "stability", "--omega", "1"], "required: --out"),
])
def test_spans_are_checked_in_one_line(args, says):
    out = run(*args)
    assert out.returncode == 2 and out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], out.stderr


def test_every_command_prints_its_help():
    """``lindstedt COMMAND --help`` formats for every command (argparse expands % in a help
    text: a stray one was a traceback)."""
    from lindstedt.cli import COMMANDS, build_parser

    commands = build_parser()._subparsers._group_actions[0].choices
    for command in COMMANDS:
        assert command.name in commands[command.name].format_help()


@pytest.mark.parametrize("command", [
    ("driven", "--eps", "0.1", "--force", "0.3", "--omega", "1.2"),
    ("subharmonic", "--eps", "0.1", "--force", "2", "--omega", "3"),
    ("mixing", "--eps", "0.1", "--Q", "20", "--drive", "0.2@1.1", "--drive", "0.2@1.3"),
])
def test_the_duffing_preset_takes_the_notes_flags(command):
    """``COMMAND duffing --eps …`` is the notes' driven Duffing, as ``COMMAND --eps …``: the
    preset's name takes every flag its form without MODEL takes (the same JSON), and without
    them it is refused as that form is."""
    name, *flags = command
    plain = run(name, *flags, "--json")
    preset = run(name, "duffing", *flags, "--json")
    assert plain.returncode == preset.returncode == 0, preset.stderr
    assert json.loads(preset.stdout) == json.loads(plain.stdout)
    bare = run(name, "duffing")
    assert bare.returncode == 2 and bare.stderr.count("\n") == 1
    assert "required" in bare.stderr


@pytest.mark.parametrize("p, q", [(1, 3), (-7, 10**330), (10**400, 3), (146243431169, 10**332),
                                  (-2**70, 3**50), (3, 2**1074), (0, 1)])
def test_a_long_rational_reads_as_its_twelve_digits_even_beyond_double_range(p, q):
    """The tables' decimal of an exact coefficient (series at order 300 reaches 1e-330): never
    0 for a nonzero number, never a subnormal's false digits; against mpmath at 30 digits."""
    import mpmath
    from flint import fmpq
    from lindstedt.cli.system import _decimal

    text = _decimal(fmpq(p, q))
    with mpmath.workdps(30):
        truth = mpmath.mpf(p) / q
        assert (text == "0") == (p == 0)
        if p:
            assert abs(mpmath.mpf(text) / truth - 1) < 5e-12
