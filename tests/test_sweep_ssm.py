"""``sweep ssm SYSTEM``: one mode's spectral submanifold at each point of a grid, on Dask, into
Zarr; the stored numbers against :func:`analysis.ssm.reduce` called here, point by point; one
SSM per distinct M, C, K and f (a drive axis reuses it); refusals in one line."""

from __future__ import annotations

import json

import numpy as np
import pytest
from lindstedt.analysis.ssm_forced import reduce
from lindstedt.cli import main
from lindstedt.derive.system import parse_system
from lindstedt.sweep import kinds
from lindstedt.sweep.kinds import kind_of
from lindstedt.sweep.store import local_cluster, open_sweep, serial_sweep

SYSTEM = ("x1'' + c*x1' + 2*x1 - x2 + x1**3 = f*cos(w*t); "
          "x2'' + c*x2' + 2*x2 - x1 + 0.5*x2**2 = 0")
DRIVES = ("1/200", "1/100", "3/200", "1/50")
# NOTE: the last drive is past the hardening fold: its forced response has two folds.
SPAN, POINTS = (0.9, 1.2), 121


def test_a_drive_axis_stores_reduce_s_numbers_from_one_ssm(tmp_path, capsys):
    """``sweep ssm SYSTEM --axis f=…`` on a 2-worker cluster: each point's peaks, the ω and ρ
    of its largest state, its folds, ``|λ|``, ζ and γ₁ equal ``reduce`` at that point (its own
    SSM, in this process); every worker computed one SSM (its warm-up's, whose M, C, K, f are
    every point's), the block's points reusing it."""
    from distributed import Client

    store = tmp_path / "s.zarr"
    with local_cluster(2) as cluster, Client(cluster, set_as_default=False) as client:
        assert main(["sweep", "ssm", SYSTEM, "--axis", "f=" + ",".join(DRIVES), "--param",
                     "c=1/50", "--mode", "1", "--order", "7", "--omega",
                     f"{SPAN[0]}:{SPAN[1]}:{POINTS}", "--out", str(store), "--scheduler",
                     cluster.scheduler_address, "--json"]) == 0
        cached = client.run(kinds.ssm_of.cache_info)
    out = json.loads(capsys.readouterr().out)
    assert out["complete"] and out["refused_points"] == 0
    assert {"peak_x1", "peak_x2", "omega_peak", "folds", "gamma1_re"} <= set(out["fields"])
    assert all(c.misses == 1 and c.currsize == 1 for c in cached.values()), cached
    assert sum(c.hits for c in cached.values()) >= len(DRIVES)
    ds = open_sweep(store).load()
    for i, f in enumerate(DRIVES):
        red = reduce(parse_system(SYSTEM, {"f": f, "c": "1/50"}, driven=True), 1, 7,
                     span=SPAN, points=POINTS)
        states = red.response.states
        top = max(states, key=lambda s: s.rho)
        point = ds.isel(f=i)
        for name, peak in zip(red.names, np.max([s.amplitude for s in states], axis=0),
                              strict=True):
            assert abs(float(point[f"peak_{name}"]) - peak) <= 1e-12
        assert abs(float(point.omega_peak) - top.omega) <= 1e-12
        assert abs(float(point.rho_peak) - top.rho) <= 1e-12
        assert int(point.folds) == len(red.response.folds) == (2 if f == "1/50" else 0)
        assert int(point.beyond_radius) == int(red.response.beyond > 0) == 0
        lam, gamma1 = red.model.lam, red.model.gamma[1]
        assert abs(float(point.omega0) - abs(lam)) <= 1e-12
        assert abs(float(point.damping_ratio0) + lam.real / abs(lam)) <= 1e-12
        assert abs(complex(float(point.gamma1_re), float(point.gamma1_im)) - gamma1) <= 1e-12


def test_one_ssm_per_linear_part_and_refused_points_stored_as_nan():
    """In this process: over f × c, one SSM per value of c (the f axis reuses it); a point
    whose SSM is refused (c = 0: 3λ₁ = λ₂, an internal resonance) holds NaN and folds −1, its
    neighbour the forced response; f = 0 is the rest state."""
    kind = kind_of("ssm", SYSTEM, {}, ["f", "c"], order=5, omega=(0.9, 1.2, 21))
    kinds.ssm_of.cache_clear()
    ds = serial_sweep(kind, {"f": [0.005, 0.01, 0.02], "c": [0.02, 0.05]})
    info = kinds.ssm_of.cache_info()
    assert (info.misses, info.hits) == (2, 4)
    assert np.all(ds.peak_x1.values > 0) and np.all(ds.folds.values >= 0)
    resonant = "x1'' + c*x1' + x1 + x1**3 + x1*x2 = f*cos(w*t); x2'' + c*x2' + 9*x2 + x1**2 = 0"
    ds = serial_sweep(kind_of("ssm", resonant, {}, ["c", "f"], order=5),
                      {"c": [0.0, 0.02], "f": [0.0, 0.01]})
    assert ds.folds.values.tolist() == [[-1, -1], [0, 2]]
    assert np.isnan(ds.omega0.values[0]).all() and np.isnan(ds.peak_x1.values[0]).all()
    assert float(ds.peak_x1.values[1, 0]) == 0.0 and float(ds.peak_x1.values[1, 1]) > 0


@pytest.mark.parametrize("axis, says", [("zz=1:2:2", "zz: not a parameter of"),
                                        ("w=1:2:2", "--axis w: w is the drive frequency")])
def test_refusals_in_one_line(tmp_path, capsys, axis, says):
    store = tmp_path / "s.zarr"
    assert main(["sweep", "ssm", SYSTEM, "--axis", axis, "--param", "c=1/50", "--param",
                 "f=1/100", "--out", str(store)]) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and len(err.splitlines()) == 1, err
    assert not store.exists()
