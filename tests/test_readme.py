"""Every example of README.md runs as printed after a plain install.

The README's examples are read from its fenced blocks:

* ```` ```console ````: each ``$ lindstedt …`` line (``\\`` continues it) is run, and each output
  line shown under it must appear in what the command prints; a line that is ``…`` or ends
  with ``…`` is a cut (only the text before ``…`` must appear), for long or timed output.
* ```` ```sh ````: each ``lindstedt …`` line is run (``make``, ``pip`` and ``jupyter`` lines are
  the reader's, not the suite's: the suite already runs in an installed venv).
* ```` ```python ````: the block runs with ``python -c``; a comment ``→ value`` after a ``print``
  must appear in its output (up to a ``…``).

An HTML comment on the line before a block changes how it runs: ``<!-- not run: reason -->``
skips it, ``<!-- exit status N -->`` expects status N from each of its commands (0 otherwise).
The blocks of one ``##`` section run in order in one temporary folder (so ``generate … --out
mine`` precedes the Python that imports from ``mine``), each section as its own test.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
from commands import cached_env, run

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
CUT = "…"
TIMEOUT = 120
# NOTE: generous, so a loaded machine does not fail an example; each takes seconds.
MARK = re.compile(r"<!--\s*(not run:.*|exit status \d+)\s*-->")
ARROW = re.compile(r"#.*?→\s*(.+?)\s*$")


@dataclass(frozen=True)
class Step:
    """One thing to run: a command (argv after ``lindstedt``) or a Python source."""

    line: int
    kind: str  # "command" or "python"
    text: str
    shown: tuple[str, ...] = ()  # output lines to find
    status: int = 0


def _command(lines: list[str], start: int) -> tuple[str, int]:
    """The command beginning at ``lines[start]``, joined over ``\\`` continuations."""
    text, i = lines[start], start
    while text.endswith("\\"):
        i += 1
        text = text[:-1].rstrip() + " " + lines[i].strip()
    return text, i + 1


def _console(body: list[str], first: int, status: int) -> list[Step]:
    steps, i = [], 0
    while i < len(body):
        if not body[i].startswith("$ "):
            i += 1
            continue
        line = first + i
        text, i = _command(body, i)
        start = i
        while i < len(body) and not body[i].startswith("$ "):
            i += 1
        if text[2:].startswith("lindstedt "):
            shown = tuple(x for x in body[start:i] if x.strip())
            steps.append(Step(line, "command", text[2:], shown, status))
    return steps


def _sh(body: list[str], first: int, status: int) -> list[Step]:
    steps, i = [], 0
    while i < len(body):
        if body[i].startswith("lindstedt "):
            line = first + i
            text, i = _command(body, i)
            steps.append(Step(line, "command", text.split(" #")[0], (), status))
        else:
            i += 1
    return steps


def readme_sections() -> dict[str, list[Step]]:
    """The README's runnable steps, by ``##`` section, in the order they appear."""
    lines = README.read_text(encoding="utf-8").splitlines()
    sections: dict[str, list[Step]] = {}
    section, mark, i = "top", None, 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("## "):
            section = line[3:].strip()
        found = MARK.fullmatch(line.strip())
        if found:
            mark = found.group(1)
            i += 1
            continue
        fence = re.fullmatch(r"```(\w*)", line)
        if fence:
            end = lines.index("```", i + 1)
            body, lang = lines[i + 1:end], fence.group(1)
            if not (mark or "").startswith("not run"):
                status = int(mark.split()[-1]) if mark else 0
                if lang == "console":
                    steps = _console(body, i + 2, status)
                elif lang == "sh":
                    steps = _sh(body, i + 2, status)
                elif lang == "python":
                    steps = [Step(i + 2, "python", "\n".join(body), (), 0)]
                else:
                    steps = []
                sections.setdefault(section, []).extend(steps)
            i, mark = end + 1, None
            continue
        if line.strip():
            mark = None
        i += 1
    return {name: steps for name, steps in sections.items() if steps}


SECTIONS = readme_sections()


def _expected(shown: str) -> str:
    """The part of a shown output line that must appear: all of it, or the text before a cut."""
    text = shown.strip()
    return text[: text.index(CUT)].rstrip() if CUT in text else text


def _run(step: Step, cwd: Path) -> subprocess.CompletedProcess:
    """A command in this process (tests/commands.py: the same parse, checks, output and exit
    status as the ``lindstedt`` script, without its second of imports); a Python block in a
    fresh interpreter, as a reader runs it, sharing the suite's numba cache."""
    if step.kind == "command":
        return run(*shlex.split(step.text)[1:], cwd=cwd)
    env = {**cached_env(), "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-c", step.text], cwd=cwd, capture_output=True,
                          text=True, timeout=TIMEOUT, env=env, check=False)


def test_readme_has_examples():
    steps = [s for section in SECTIONS.values() for s in section]
    assert sum(s.kind == "command" for s in steps) >= 15
    assert sum(s.kind == "python" for s in steps) >= 3


@pytest.mark.parametrize("section", list(SECTIONS))
def test_readme_section_runs_as_printed(section: str, tmp_path: Path):
    for step in SECTIONS[section]:
        done = _run(step, tmp_path)
        where = f"README.md line {step.line}: {step.text.splitlines()[0]}"
        printed = done.stdout + done.stderr
        assert done.returncode == step.status, f"{where}: exit {done.returncode}\n{printed}"
        assert "deprecated" not in done.stderr, f"{where}: an old spelling\n{done.stderr}"
        wanted = list(step.shown)
        if step.kind == "python":
            wanted = [m.group(1) for m in map(ARROW.search, step.text.splitlines()) if m]
        for shown in wanted:
            text = _expected(shown)
            if text:
                assert text in printed, f"{where}: not printed: {text!r}\n{printed}"


def test_readme_links_exist():
    text = README.read_text(encoding="utf-8")
    links = re.findall(r"\]\(((?:docs/)[^)#]+)\)", text)
    assert links
    missing = [link for link in links if not (ROOT / link).exists()]
    assert not missing, missing


def test_readme_is_short():
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 380
