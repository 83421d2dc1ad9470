"""The layout: every module of the package is a stage of ``lindstedt/__init__.py``'s list (or
one of the modules beside it), the folders hold their stages in the list's order, and a stage
imports only stages listed above it."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import lindstedt

PACKAGE = Path(lindstedt.__file__).resolve().parent
BESIDE = {"errors", "limits", "display"}
# NOTE: beside the stages (the docstring says so): they import no stage, and any stage may
# import them.
LIMIT = 1000
# NOTE: no module over about 1 000 lines; the command line's parser and formatters are the
# exceptions named for the layout, split by command family.


def stages() -> list[str]:
    """The stage names (dotted: ``folder.module``), in order, from the docstring's list."""
    return re.findall(r"^    ([a-z_.]+) {2,}", lindstedt.__doc__, flags=re.MULTILINE)


def dotted(path: Path) -> str:
    """``analysis/driven.py`` -> ``analysis.driven``; a folder's ``__init__`` -> the folder."""
    parts = path.relative_to(PACKAGE).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {dotted(p): p for p in PACKAGE.rglob("*.py") if dotted(p) not in {"", "__main__"}}


def imported(path: Path, known: set[str], where: str | None = None) -> set[str]:
    """The package modules ``path`` imports (relative or absolute, at any depth: the command
    line imports its stages inside its functions), as dotted names; ``where``: the file's
    place in the package (``analysis/driven.py``), default its own."""
    place = Path(where) if where else path.relative_to(PACKAGE)
    here = list(place.with_suffix("").parts)  # a module's own name, or __init__, is last
    tree = ast.parse(path.read_text(encoding="utf-8"))
    typing_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If)
                   and ast.unparse(block.test) == "TYPE_CHECKING" for n in ast.walk(block)}
    found = set()
    for node in ast.walk(tree):
        if id(node) in typing_only:  # names for annotations only: no import at run time
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                head = [*here[: len(here) - node.level],
                        *(node.module.split(".") if node.module else [])]
            elif node.module and node.module.split(".")[0] == "lindstedt":
                head = node.module.split(".")[1:]
            else:
                continue
            names = {".".join([*head, a.name]) for a in node.names}
            found |= names & known
            if names - known:  # names from a module (or a folder's __init__)
                found |= {".".join(head)} & known
        elif isinstance(node, ast.Import):
            found |= {a.name.split(".", 1)[1] for a in node.names
                      if a.name.startswith("lindstedt.") and a.name.split(".", 1)[1] in known}
    return found


def test_the_stage_list_names_every_module_once():
    listed = stages()
    assert len(listed) == len(set(listed))
    folders = {name for name in modules() if (PACKAGE / name.replace(".", "/")).is_dir()}
    assert set(listed) | BESIDE == set(modules()) - (folders - set(listed))


def test_the_folders_hold_their_stages_together_and_in_order():
    seen: list[str] = []
    for name in stages():
        folder = name.split(".")[0] if "." in name else name
        if folder in seen and seen[-1] != folder:
            raise AssertionError(f"{name}: its folder {folder} is split by {seen[-1]}")
        if not seen or seen[-1] != folder:
            seen.append(folder)


def test_every_import_follows_the_stage_list():
    order = {name: i for i, name in enumerate(stages())}
    known = set(modules())
    wrong = []
    for me, path in sorted(modules().items()):
        for other in sorted(imported(path, known) - {me}):
            if other in BESIDE:
                continue
            if me in BESIDE:
                wrong.append(f"{me} (beside the stages) imports {other}")
            elif me not in order:
                wrong.append(f"{me} (a folder's __init__) imports {other}")
            elif other not in order or order[other] >= order[me]:
                wrong.append(f"{me} imports {other}, listed after it")
    assert not wrong, "; ".join(wrong)


def test_every_relative_import_names_a_module_of_the_package():
    """A function-level import that names no module (``from .kinds import`` where the module
    is ``sweep.kinds``) fails only when that function runs: caught here, for every one."""
    known = set(modules())
    wrong = []
    for me, path in sorted(modules().items()):
        here = list(path.relative_to(PACKAGE).with_suffix("").parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level:
                head = [*here[: len(here) - node.level],
                        *(node.module.split(".") if node.module else [])]
                name = ".".join(head)
                if name and name not in known and name != "__init__":
                    wrong.append(f"{me}: from {'.' * node.level}{node.module or ''}")
    assert not wrong, "; ".join(wrong)


def test_every_name_imported_inside_the_package_exists():
    """Every ``from .x import y`` in the package, at any depth (a command's imports run only
    when it does), names a module that imports and a name it holds."""
    import importlib

    wrong = []
    for me, path in sorted(modules().items()):
        here = list(path.relative_to(PACKAGE).with_suffix("").parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.ImportFrom) and node.level):
                continue
            head = [*here[: len(here) - node.level],
                    *(node.module.split(".") if node.module else [])]
            name = ".".join(["lindstedt", *head])
            module = importlib.import_module(name)
            for alias in node.names:
                if not hasattr(module, alias.name):
                    try:
                        importlib.import_module(f"{name}.{alias.name}")
                    except ImportError:
                        wrong.append(f"{me}: {alias.name} from {name}")
    assert not wrong, "; ".join(wrong)


def test_every_folder_is_a_package_of_the_wheel():
    """pyproject lists the packages a wheel carries: each folder of the source, or a plain
    ``pip install .`` lacks it (the editable install would not notice)."""
    import tomllib

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]
                 ["setuptools"]["packages"])
    folders = {"lindstedt." + p.parent.name for p in PACKAGE.glob("*/__init__.py")}
    assert folders | {"lindstedt", "lindstedt.templates"} == listed


def test_no_module_is_over_the_limit():
    long = {name: n for name, path in modules().items()
            if (n := len(path.read_text(encoding="utf-8").splitlines())) > LIMIT}
    assert not long, long


def test_the_import_reader_sees_late_and_relative_imports(tmp_path):
    """The check can fail: a function-level import of a later stage is seen."""
    source = tmp_path / "x.py"
    source.write_text("from ..emit.render import render\n\ndef f():\n    from ..cli import main\n"
                      "    from .. import choose\n    from . import driven\n"
                      "    import lindstedt.sweep\n")
    assert imported(source, set(modules()), "analysis/x.py") == {
        "emit.render", "cli", "choose", "analysis.driven", "sweep"}


def test_only_the_parser_splits_a_text_into_equations():
    """No command, cost or method asks whether a text holds a ';' (or counts them): the one
    problem record (derive.problem) does, and routes ask the record."""
    parsers = {"derive.problem", "derive.equation"}
    found = []
    for name, path in modules().items():
        if name in parsers:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            asks = (isinstance(node, ast.Compare) and _semicolon(node.left)
                    and isinstance(node.ops[0], ast.In | ast.NotIn))
            splits = (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                      and node.func.attr in ("split", "count", "partition")
                      and any(map(_semicolon, node.args))
                      and not (isinstance(node.func.value, ast.Name)
                               and node.func.value.id == "message"))  # an error's own text
            if asks or splits:
                found.append(f"{name}:{node.lineno}")
    assert not found, found


def _semicolon(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and node.value == ";"


def test_a_command_routes_its_problem_to_the_first_method_that_takes_it():
    import argparse

    from lindstedt.cli import COMMAND
    from lindstedt.derive.problem import read_problem

    pair = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
    assert read_problem(pair).equations == ("x1'' + 2*x1 - x2 + x1**3/2 = 0",
                                            "x2'' + 2*x2 - x1 = 0")
    assert read_problem("vdp").equations == ("q'' + q = eps*(1 - q**2)*q'",)
    assert read_problem("vdp").preset == "van_der_pol"
    assert read_problem("driven").size == 0 and read_problem("driven").preset is None
    for command, system in (("generate", "normal mode"), ("response", "response"),
                            ("slowflow", "resonant flow")):
        route = COMMAND[command].route
        assert route(argparse.Namespace(model=pair)).method == system
        for one in ("q'' + q + q**3 = 0", "duffing", "driven"):
            assert route(argparse.Namespace(model=one)).method == command
    assert COMMAND["response"].route(argparse.Namespace(model=None)).method == "response"
