"""The package as a user gets it: a wheel built from the source, installed into a fresh venv
(not editable), used from folders outside the checkout; and `make demo` in a clean clone.

One venv serves every test here, on whichever pytest-xdist worker runs it (building it costs
~1 min, mostly unpacking the dependencies from pip's cache).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest
from commands import cached_env, made_once
from scipy.special import ellipk

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("pyproject.toml", "README.md", "generator", "templates")
# NOTE: what the build needs; copied, so that building leaves nothing in the checkout.


def _run(cmd: list, cwd: Path, timeout: float = 900, env: dict | None = None
         ) -> subprocess.CompletedProcess:
    """``cmd`` in ``cwd``, writing bytecode as it imports (as a user's Python does): the wheel
    is installed ``--no-compile``, and where ``PYTHONDONTWRITEBYTECODE`` is set every process
    would compile SymPy, SciPy and NumPy from source again."""
    env = {k: v for k, v in (os.environ if env is None else env).items()
           if k != "PYTHONDONTWRITEBYTECODE"}
    out = subprocess.run([str(c) for c in cmd], cwd=cwd, capture_output=True, text=True,
                         timeout=timeout, check=False, env=env)
    assert out.returncode == 0, f"{cmd}\n{out.stdout[-2000:]}\n{out.stderr[-4000:]}"
    return out


@pytest.fixture(scope="module")
def venv(run_folder) -> Path:
    """A fresh venv holding the wheel of this checkout and its dependencies, built once in the
    run's folder: a pytest-xdist worker that needs it while another builds it waits for it."""
    return made_once(run_folder / "install", _build) / "venv"


def _build(work: Path) -> None:
    """The wheel of this checkout, built from a copy of its sources, installed into
    ``work/venv``."""
    src = work / "src"
    src.mkdir()
    for name in SOURCES:
        (shutil.copytree if (ROOT / name).is_dir() else shutil.copy)(ROOT / name, src / name)
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", work / "dist",
          src], work)
    (wheel,) = (work / "dist").glob("lindstedt-*.whl")
    base = Path(getattr(sys, "_base_executable", sys.executable))
    _run([base, "-m", "venv", work / "venv"], work)
    # NOTE: the pinned versions of make test (constraints.txt), so the wheel meets what CI had.
    # NOTE: --no-compile: byte-compiling every dependency up front (SymPy, SciPy, matplotlib)
    # is half the install's time; Python compiles what the tests import as it imports it.
    _run([work / "venv/bin/python", "-m", "pip", "install", "--quiet", "--no-compile", "-c",
          ROOT / "constraints.txt", wheel], work)


def test_import_name_is_lindstedt_and_nothing_called_generator(venv, tmp_path):
    py = venv / "bin/python"
    out = _run([py, "-c", "import lindstedt, lindstedt.emit.render as e; "
                "print(lindstedt.__file__); print(e.template_folder())"], tmp_path)
    package, templates = out.stdout.split()
    site = Path(_run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                     tmp_path).stdout.strip())
    assert Path(package).parent == site / "lindstedt"
    assert Path(templates) == site / "lindstedt" / "templates"
    assert not (site / "generator").exists()
    bad = subprocess.run([py, "-c", "import generator"], cwd=tmp_path, capture_output=True,
                         text=True, check=False)
    assert bad.returncode != 0 and "No module named 'generator'" in bad.stderr
    assert sysconfig.get_paths()["purelib"] != str(site)  # really another environment


def test_generate_from_another_folder(venv, tmp_path):
    """`generate` renders its templates from the wheel; the emitted period matches the exact
    elliptic period 4K(m)/√(1+x), m = x/(2(1+x)), to the series' truncation error."""
    _run([venv / "bin/lindstedt", "generate", "duffing", "--order", "8", "--out", "gen"],
         tmp_path, env=cached_env())
    assert {p.name for p in (tmp_path / "gen").iterdir()} >= {
        "duffing.py", "duffing_tables.tex", "duffing_derivation.tex"}
    x = np.array([0.05, 0.1, 0.2])
    probe = ("import sys; sys.path.insert(0, 'gen'); import duffing, numpy as np; "
             f"print(*duffing.period(1.0, np.array({x.tolist()})))")
    series = np.array(_run([venv / "bin/python", "-c", probe], tmp_path,
                           env=cached_env()).stdout.split(), dtype=float)
    exact = 4 * ellipk(x / (2 * (1 + x))) / np.sqrt(1 + x)
    assert np.max(np.abs(series / exact - 1)) < 2 * 0.2**9


def test_choose_emit_from_another_folder(venv, tmp_path):
    out = _run([venv / "bin/lindstedt", "choose", "period", "--tol", "1e-6", "--range", "0:0.3",
                "--out", "em", "--json"], tmp_path, env=cached_env())
    assert '"emitted"' in out.stdout
    probe = ("import sys; sys.path.insert(0, 'em'); import chosen_period as c; "
             "print(c.period(1.0, 0.25))")
    period = float(_run([venv / "bin/python", "-c", probe], tmp_path, env=cached_env()).stdout)
    # NOTE: cached_env: the module choose verified and the one it wrote compile once
    exact = 4 * ellipk(0.25 / 2.5) / np.sqrt(1.25)
    assert abs(period / exact - 1) < 1e-6


def test_make_demo_in_a_clean_clone_leaves_git_status_clean(venv, tmp_path):
    """`make demo` (here with the wheel's venv, so the templates come from the wheel) writes
    only under out/: the clone's `git status --porcelain` stays empty."""
    clone = tmp_path / "clone"
    _run(["git", "clone", "--quiet", ROOT, clone], tmp_path)
    stamp = venv / ".installed"
    stamp.touch()
    # NOTE: -o: the venv is ready; make must not reinstall the clone into it.  The demo's
    # modules are the committed ones (generated/): compiled once for the whole suite.
    _run(["make", "--no-print-directory", "demo", f"VENV={venv}", "-o", stamp], clone,
         timeout=1800, env=cached_env())
    status = _run(["git", "status", "--porcelain", "--ignored=no"], clone).stdout
    assert status == ""
    written = {p.relative_to(clone / "out").as_posix() for p in (clone / "out").rglob("*")}
    assert {"duffing.py", "pendulum.py", "driven.py", "balance.py", "figures/response.png",
            "figures/mixing.png", "duffing_derivation.pdf"} <= written
