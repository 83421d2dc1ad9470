"""The emitted reduced model of an SSM (``generate SYSTEM --ssm M``): its ufuncs, amplitude and
forced response against the in-process SSM it was lowered from (the forcing interpolated on
Chebyshev nodes), the drive's scaling against a system written with twice the drive, NaN
outside its range, byte-identical regeneration, a model folder, and bad input."""

from __future__ import annotations

import importlib.util
import sys

import numpy as np
import pytest
from commands import run
from lindstedt.analysis.ssm import ssm
from lindstedt.analysis.ssm_forced import forced_response
from lindstedt.derive.system import parse_system
from test_ssm import PAIR


@pytest.fixture(scope="module")
def emitted(tmp_path_factory):
    out = tmp_path_factory.mktemp("ssm")
    done = run("generate", PAIR, "--param", "f=1/100", "--ssm", "1", "--order", "9",
               "--omega", "0.9:1.1", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == [str(out / "ssm1.py"), str(out / "ssm1_reduced.tex")]
    spec = importlib.util.spec_from_file_location("ssm1", out / "ssm1.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["ssm1"] = module  # as `import ssm1` does: numba's cache finds its callees
    spec.loader.exec_module(module)
    return out, module


def test_backbone_equals_the_ssm(emitted):
    _, m = emitted
    model = ssm(parse_system(PAIR, {"f": "1/100"}, driven=True), 1, 9)
    rho = np.linspace(0, 0.9 * model.radius, 9)
    np.testing.assert_allclose(m.omega(rho), model.omega(rho), rtol=1e-14)
    np.testing.assert_allclose(m.damping(rho), model.damping_ratio(rho), rtol=1e-12)
    np.testing.assert_allclose(m.decay(rho), model.decay(rho), rtol=1e-12)
    for r in rho[1:]:
        np.testing.assert_allclose(m.amplitude(r), model.amplitude(np.array([r]),
                                                                   np.arange(2))[0],
                                   rtol=1e-12)
    assert np.isnan(m.omega(1.01 * m.RADIUS)) and np.isnan(m.omega(-0.1))
    assert np.isnan(m.damping(np.nan)) and np.all(np.isnan(m.amplitude(np.inf)))


@pytest.mark.parametrize("f, text", [(1.0, "1/100"), (2.0, "1/50")])
def test_forced_response_equals_the_ssm(emitted, f, text):
    """frc(w, f) against the in-process forced response of the system written with the drive
    f times as large (S and X are linear in the drive)."""
    _, m = emitted
    model = ssm(parse_system(PAIR, {"f": text}, driven=True), 1, 9)
    omegas = np.array([0.9, 0.97, 1.003, 1.01, 1.02, 1.1])
    response = forced_response(model, omegas, np.arange(2))
    for w in omegas:
        states = [s for s in response.states if s.omega == w]
        rho, amp, stable = m.frc(w, f)
        found = np.isfinite(rho)
        assert found.sum() == len(states)
        for k, s in enumerate(sorted(states, key=lambda s: s.rho)):
            assert abs(rho[k] - s.rho) <= 1e-9 * s.rho
            np.testing.assert_allclose(amp[k], s.amplitude, rtol=1e-9)
            assert stable[k] == float(s.stable)
    assert np.all(np.isnan(m.frc(1.2, 1.0)[0])) and np.all(np.isnan(m.frc(1.0, np.nan)[0]))


def test_regeneration_is_byte_identical_and_the_latex_holds_the_flow(emitted, tmp_path):
    out, _ = emitted
    done = run("generate", PAIR, "--param", "f=1/100", "--ssm", "1", "--order", "9",
               "--omega", "0.9:1.1", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    for name in ("ssm1.py", "ssm1_reduced.tex"):
        assert (tmp_path / name).read_bytes() == (out / name).read_bytes()
    tex = (out / "ssm1_reduced.tex").read_text()
    assert r"\omega(\rho) &= 0.99994999875 + 0.0833280165813\,\rho^{2}" in tex


@pytest.mark.parametrize("args, says", [
    (["--ssm", "1", "--mode", "2"], "--mode: not for an SSM"),
    (["--ssm", "1", "--order", "50"], "order 1..41"),
    (["--ssm", "1", "--omega", "1.2:1.1"], "0 < A < B"),
])
def test_bad_input(args, says, tmp_path):
    done = run("generate", PAIR, "--param", "f=1/100", *args, "--out", str(tmp_path))
    assert done.returncode == 2 and says in done.stderr and len(done.stderr.splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_model_folder_without_ssm_is_refused(tmp_path):
    done = run("generate", "--model", str(tmp_path), "--out", str(tmp_path))
    assert done.returncode == 2 and "--ssm M" in done.stderr
