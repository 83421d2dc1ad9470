"""The suite's three layers, as markers:

* ``exact``: exact identities and in-process numerics against independent references (series
  against elliptic integrals, DLMF, product-to-sum, quadrature, shooting); nothing is emitted.
* ``printers``: the command line, JSON contracts, tables, LaTeX, files, charts, the fuzzer.
* ``emitted``: generated numba modules compiled and checked against references, the wheel in a
  fresh venv, ``make demo``, Dask clusters.

``make test`` runs every layer in one pytest run on every core (pytest-xdist); ``make
test-fast`` (``pytest -m exact``) the exact layer alone, in about three minutes on two cores.  A
module's layer is where its slowest test belongs.

The run hands out whole files (``--dist loadfile``: a module's fixtures are set up once), the
longest first (tests/durations.json: each file's seconds, measured by
``benchmarks/suite_times.py --write-durations``; a file it does not list counts as ``SHORT``),
each to the first idle worker, so that no worker ends with a long file while the others wait.
The order only schedules: it decides no outcome.

An emitted module compiles once per run of the suite, whichever test, worker or folder loads
it: numba's cache of emitted modules is kept by their text in one folder that every worker
shares (tests/commands.py, ``EmittedCache``)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from commands import CACHE_VARIABLE, EmittedCache
from numba.core.caching import CacheImpl

LAYERS = {
    "exact": ("attractors", "averaging", "beam_model", "branches", "continuation", "driven",
              "driven_damped",
              "driven_equation",
              "equation",
              "hill", "layout", "lindstedt", "newton", "nnm", "parametric", "response",
              "response_equation",
              "response_system",
              "resonance", "series", "ssm", "ssm_exact", "ssm_resonant", "subharmonic", "toolkit"),
    "printers": ("charts", "cli", "costs", "curves", "emit", "files", "fuzz", "interrupt", "latex",
                 "messages", "notebook", "readme", "validity"),
    "emitted": ("choose", "emitted_safety", "install", "limit_cycle", "mass", "nnm_emitted",
                "orbits",
                "orbit_domain_grid",
                "oscillator", "resum", "ssm_emitted", "sweep", "sweep_ssm", "tongues"),
}
LAYER_OF = {f"test_{name}.py": layer for layer, names in LAYERS.items() for name in names}


def pytest_configure(config: pytest.Config) -> None:
    for layer in LAYERS:
        config.addinivalue_line("markers", f"{layer}: a layer of the suite (tests/conftest.py)")


DURATIONS = Path(__file__).with_name("durations.json")
SHORT = 1.0  # seconds: a test file durations.json does not list


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        name = Path(str(item.fspath)).name
        if name not in LAYER_OF:
            raise pytest.UsageError(f"{name}: give it a layer in tests/conftest.py")
        item.add_marker(getattr(pytest.mark, LAYER_OF[name]))
    seconds = json.loads(DURATIONS.read_text(encoding="utf-8"))
    items.sort(key=lambda item: -seconds.get(Path(str(item.fspath)).name, SHORT))  # stable


@pytest.fixture(scope="session")
def run_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The run's temporary folder, which every pytest-xdist worker of the run shares (each
    worker's own folder is made in it): a fresh one each run."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@pytest.fixture(scope="session", autouse=True)
def emitted_cache(run_folder: Path):
    """numba's cache of emitted modules for this run: ``numba-cache`` in the run's folder (so
    each distinct module is compiled once in every run)."""
    folder = run_folder / "numba-cache"
    folder.mkdir(exist_ok=True)
    os.environ[CACHE_VARIABLE] = str(folder)
    CacheImpl._locator_classes.insert(0, EmittedCache)
    yield folder
    CacheImpl._locator_classes.remove(EmittedCache)
    del os.environ[CACHE_VARIABLE]
