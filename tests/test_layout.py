"""The layout: every module of the package is a stage of ``lindstedt/__init__.py``'s list (or
one of the modules beside it), and a stage imports only stages listed above it."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import lindstedt

PACKAGE = Path(lindstedt.__file__).resolve().parent
BESIDE = {"errors", "display"}
# NOTE: beside the stages (the docstring says so): they import no stage, and any stage may
# import them.


def stages() -> list[str]:
    """The stage names, in order, from the package docstring's indented list."""
    return re.findall(r"^    ([a-z_]+) {2,}", lindstedt.__doc__, flags=re.MULTILINE)


def imported(path: Path) -> set[str]:
    """The package modules ``path`` imports (relative or absolute, at any depth: the command
    line imports its stages inside its functions)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level == 1 and node.module:
                found.add(node.module.split(".")[0])
            elif node.level == 1:  # from . import x: x a module, or a name of __init__
                found |= {a.name for a in node.names}
            elif node.module and node.module.split(".")[0] == "lindstedt":
                parts = node.module.split(".")
                found |= {parts[1]} if len(parts) > 1 else {a.name for a in node.names}
        elif isinstance(node, ast.Import):
            found |= {a.name.split(".")[1] for a in node.names
                      if a.name.startswith("lindstedt.")}
    modules = {p.stem for p in PACKAGE.glob("*.py")}
    return found & modules


def test_the_stage_list_names_every_module_once():
    listed = stages()
    assert len(listed) == len(set(listed))
    modules = {p.stem for p in PACKAGE.glob("*.py")} - {"__init__", "__main__"}
    assert set(listed) | BESIDE == modules


def test_every_import_follows_the_stage_list():
    order = {name: i for i, name in enumerate(stages())}
    wrong = []
    for path in sorted(PACKAGE.glob("*.py")):
        me = path.stem
        for other in sorted(imported(path)):
            if other in BESIDE or me == "__main__":
                continue
            if me in BESIDE:
                wrong.append(f"{me} (beside the stages) imports {other}")
            elif other not in order or order[other] >= order[me]:
                wrong.append(f"{me} imports {other}, listed after it")
    assert not wrong, "; ".join(wrong)


def test_the_import_reader_sees_late_and_relative_imports(tmp_path):
    """The check can fail: a function-level import of a later stage is seen."""
    source = tmp_path / "x.py"
    source.write_text("from .emit import render\n\ndef f():\n    from .cli import main\n"
                      "    from . import choose\n")
    assert imported(source) == {"emit", "cli", "choose"}
