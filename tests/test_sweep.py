"""Parameter sweeps on dask.distributed into Zarr: the same numbers as the serial loop,
independent checks of single points, resuming after a stop or a kill, refusals before work."""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from lindstedt.analysis.driven import (
    Drive,
    amplitudes,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
)
from lindstedt.analysis.response import one_harmonic_curve
from lindstedt.charts import sweep_figure
from lindstedt.errors import InputError
from lindstedt.numerics.shooting import shoot
from lindstedt.sweep.kinds import (
    MU_ORDERS,
    WarmUp,
    kernel_signatures,
    kind_of,
    validity_errors,
)
from lindstedt.sweep.store import (
    estimate_bytes,
    local_cluster,
    make_grid,
    open_sweep,
    run_sweep,
    serial_sweep,
)

EPS, FORCE, Q = 0.1, 0.3, 20.0
# the notes' hardening spring: one branch below ω ≈ 1.1, three between the folds, one above
STABILITY_AXES = {"omega": [0.9, 1.1, 1.25, 1.4, 1.6, 1.8], "force": [FORCE], "eps": [EPS],
                  "Q": [Q, math.inf]}
RESPONSE_AXES = {"omega": [0.7, 1.2, 1.5], "force": [0.1, FORCE], "eps": [EPS], "Q": [Q]}
SUBHARMONIC_AXES = {"omega": [0.9, 1.5], "force": [0.1], "eps": [EPS]}
VALIDITY_AXES = {"omega": [0.6, 1.0, 1.6], "force": [1.0], "eps": [EPS], "Q": [math.inf, Q]}


@pytest.fixture(scope="module")
def scheduler():
    """One 2-worker cluster for the module: its start-up (seconds) is paid once."""
    with local_cluster(2) as cluster:
        yield cluster.scheduler_address


def test_local_cluster_equals_serial_and_shooting(tmp_path):
    """The default path (its own LocalCluster, 2 processes) against the serial loop, value for
    value; one point against a direct shooting call from the first-order root."""
    ds = run_sweep("stability", STABILITY_AXES, tmp_path / "s.zarr", workers=2, chunk=2)
    serial = serial_sweep("stability", STABILITY_AXES, chunk=2)
    xr.testing.assert_identical(ds.load(), serial)
    point = ds.sel(omega=1.25, force=FORCE, eps=EPS, Q=Q)
    assert (int(point.branches), int(point.orbits), int(point.stable_orbits)) == (3, 3, 2)
    d = Drive(EPS, FORCE, 1.25, Q)
    for k, br in enumerate(first_order_branches(d)):
        orbit = shoot(EPS, FORCE, 1.25, d.damping,
                      br.A1 * np.array([math.cos(br.delta0), 1.25 * math.sin(br.delta0)]))
        assert abs(float(point.r[k]) - math.hypot(orbit.A[1], orbit.B[1])) < 1e-9
        assert int(point.orbit_stable[k]) == int(orbit.stable)
    # the one-harmonic criterion (∂G/∂u > 0) counts the same stable branches, damped
    curve = one_harmonic_curve(EPS, FORCE, Q, np.array(STABILITY_AXES["omega"]))
    assert list(ds.stable_orbits.sel(Q=Q).values.ravel()) == list(curve.stable.sum(axis=1))


@pytest.mark.parametrize(("kind", "axes"), [("response", RESPONSE_AXES),
                                            ("subharmonic", SUBHARMONIC_AXES),
                                            ("validity", VALIDITY_AXES)])
def test_every_kind_on_a_running_scheduler_equals_serial(scheduler, tmp_path, kind, axes):
    ds = run_sweep(kind, axes, tmp_path / f"{kind}.zarr", scheduler=scheduler, chunk=2)
    xr.testing.assert_identical(ds.load(), serial_sweep(kind, axes, chunk=2))
    # consolidated metadata: xarray's own reader, with its defaults, opens it without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plain = xr.open_zarr(tmp_path / f"{kind}.zarr")
    xr.testing.assert_identical(plain.load(), serial_sweep(kind, axes, chunk=2))


def test_response_against_shooting_and_one_harmonic():
    ds = serial_sweep("response", RESPONSE_AXES)
    d = Drive(EPS, FORCE, 1.2, Q)
    branches = first_order_branches(d)
    point = ds.sel(omega=1.2, force=FORCE, eps=EPS, Q=Q)
    assert int(point.branches) == len(branches) == 3
    for k, br in enumerate(branches):
        orbit = shoot(EPS, FORCE, 1.2, d.damping,
                      br.A1 * np.array([math.cos(br.delta0), 1.2 * math.sin(br.delta0)]))
        assert abs(float(point.r[k]) - math.hypot(orbit.A[1], orbit.B[1])) < 1e-8
    # weak drive far from resonance: balance and one harmonic agree to O(ε r³)
    r1 = one_harmonic_curve(EPS, 0.1, Q, np.array([0.7])).r[0, 0]
    assert abs(float(ds.r.sel(omega=0.7, force=0.1, eps=EPS, Q=Q, branch=1)) - r1) < 1e-4
    assert float(point.r_stable_max) == float(point.r[0])
    assert float(point.r_stable_min) == float(point.r[2])  # the middle branch is the saddle


def test_validity_against_shooting_and_the_mu_series():
    """The judge (balance, N = 10) is the true orbit: A₁ within 1e-9 of shooting; the stored
    errors are |A₁(method) − A₁(judge)| recomputed here from the methods themselves."""
    ds = serial_sweep("validity", VALIDITY_AXES)
    for w in VALIDITY_AXES["omega"]:
        d = Drive(EPS, 1.0, w)
        branch = first_order_branches(d)[0]
        hb = harmonic_balance(d, branch, 10)
        a, _ = amplitudes(hb.coefficients, 0.0, 19)
        orbit = shoot(EPS, 1.0, w, 0.0, np.array([sum(a.values()), 0.0]))
        assert abs(orbit.A[1] - a[1]) < 1e-9
        point = ds.sel(omega=w, force=1.0, eps=EPS, Q=math.inf)
        mu = mu_expansion(d, branch, MU_ORDERS[-1])
        if mu.converged:
            direct = abs(amplitudes(*mu.partial(MU_ORDERS[-1]), 1)[0][1] - a[1])
            assert abs(float(point.mu_error.values[-1]) - direct) < 1e-12
    mu, _, _ = validity_errors(Drive(EPS, 1.0, 1.0))
    assert np.all(np.diff(np.log10(mu)) < 0)  # error falls with the order at ω = 1


def test_subharmonic_against_eq_10_87():
    ds = serial_sweep("subharmonic", SUBHARMONIC_AXES)
    w, f = 1.5, 0.1
    F = f / (1 - 9 * w**2)
    disc = (16 * (w**2 - 1) / EPS - 21 * F**2) / 12
    point = ds.sel(omega=w, force=f, eps=EPS)
    assert int(point.exists) == 1
    np.testing.assert_allclose(point.a.values, [-F / 2 + disc**0.5, -F / 2 - disc**0.5],
                               rtol=1e-14)
    assert int(ds.exists.sel(omega=0.9, force=f, eps=EPS)) == 0  # ω < 1: no real amplitude
    assert np.isnan(ds.a.sel(omega=0.9, force=f, eps=EPS)).all()


def test_subharmonic_full_hill_verdict_against_the_true_orbit():
    """The full Hill verdict (about the balance orbit) is the true orbit's Floquet verdict
    (shooting, RK4 monodromy) wherever both exist, its largest modulus within 1e-9 of the
    orbit's; it differs from the notes' q₀ test somewhere on the grid (a root the q₀ test calls
    stable is not); the variables stored before are all still there."""
    axes = {"omega": [0.9, 1.2, 1.5], "force": [0.1, 0.5], "eps": [EPS]}
    ds = serial_sweep("subharmonic", axes)
    assert {"exists", "F", "a", "hill_stable", "orbit_a1", "orbit_floquet", "orbit_stable",
            "locked", "stable_roots", "full_hill_stable", "full_hill_modulus"} <= set(ds)
    full, orbit = ds.full_hill_stable.values, ds.orbit_stable.values
    both = (full >= 0) & (orbit >= 0)
    assert both.sum() >= 6 and np.array_equal(full[both], orbit[both])
    finite = np.isfinite(ds.full_hill_modulus.values) & np.isfinite(ds.orbit_floquet.values)
    np.testing.assert_allclose(ds.full_hill_modulus.values[finite],
                               ds.orbit_floquet.values[finite], atol=1e-9)
    assert ((ds.hill_stable.values == 1) & (full == 0)).any()
    below = ds.sel(omega=0.9)  # ω < 1: no subharmonic, no verdict
    assert (below.full_hill_stable.values == -1).all()
    assert np.isnan(below.full_hill_modulus.values).all()
    assert ds.full_hill_stable.attrs["flag_meanings"] == "none no yes"


def test_workers_are_warmed_once_and_never_recompile(scheduler, tmp_path):
    from distributed import Client

    with Client(scheduler, set_as_default=False) as client:
        client.register_plugin(WarmUp("stability"))
        warm = client.run(kernel_signatures)
        run_sweep("stability", STABILITY_AXES, tmp_path / "a.zarr", scheduler=scheduler,
                  chunk=1)
        ints = {"omega": [1, 2], "force": [1], "eps": [0], "Q": [10]}  # ints: still float64
        run_sweep("stability", ints, tmp_path / "b.zarr", scheduler=scheduler, chunk=1)
        after = client.run(kernel_signatures)
    assert len(warm) == 2 and after == warm
    assert all(sigs["_rk4"] == 1 for sigs in after.values())


def _block_files(store: Path, grid, chunk: int) -> dict[Path, int]:
    """The chunk files of every field in block ``chunk`` and their mtimes (ns)."""
    start = [s.start // b for s, b in zip(grid.region(chunk), grid.block, strict=True)]
    out = {}
    for field in grid.kind.fields:
        key = [*start, *([0] * len(field.dims))]
        path = store / field.name / "c" / Path(*map(str, key))
        out[path] = path.stat().st_mtime_ns
    return out


def test_stopped_sweep_resumes_without_recomputing(scheduler, tmp_path):
    store = tmp_path / "s.zarr"
    first = run_sweep("stability", STABILITY_AXES, store, scheduler=scheduler, chunk=2,
                      stop_after=2)
    done = [int(i) for i in np.flatnonzero(first.done.values)]
    assert len(done) == 2
    grid = make_grid("stability", STABILITY_AXES, 2)
    before = {p: t for c in done for p, t in _block_files(store, grid, c).items()}
    computed = []
    ds = run_sweep("stability", STABILITY_AXES, store, scheduler=scheduler,
                   progress=lambda p: computed.append(p.chunk))  # chunk: the store's blocks
    assert sorted(computed + done) == list(range(grid.chunks))
    assert {p: p.stat().st_mtime_ns for p in before} == before  # finished blocks untouched
    xr.testing.assert_identical(ds.load(), serial_sweep("stability", STABILITY_AXES, chunk=2))
    # a finished store: nothing to compute, so no scheduler is even asked
    calls = []
    run_sweep("stability", STABILITY_AXES, store, scheduler="tcp://127.0.0.1:1",
              progress=calls.append)
    assert calls == []


KILLED = """
import json, os, signal, sys
import lindstedt.sweep.store as sweep
kind, axes, store, address = json.loads(sys.argv[1])
marked = []
write_flag = sweep._mark_done

def mark(arrays, chunk):
    if len(marked) == 2:  # the third block's data is written, its flag is not: die here
        os.kill(os.getpid(), signal.SIGKILL)
    marked.append(chunk)
    write_flag(arrays, chunk)

sweep._mark_done = mark
sweep.run_sweep(kind, axes, store, scheduler=address, chunk=2)
"""


def test_killed_sweep_resumes_and_recomputes_the_half_written_block(scheduler, tmp_path):
    store = tmp_path / "k.zarr"
    args = json.dumps(["stability", STABILITY_AXES, str(store), scheduler])
    run = subprocess.run([sys.executable, "-c", KILLED, args], capture_output=True, text=True,
                         timeout=120, check=False)
    assert run.returncode == -9, run.stderr
    grid = make_grid("stability", STABILITY_AXES, 2)
    killed = open_sweep(store)
    done = set(np.flatnonzero(killed.done.values).tolist())
    assert len(done) == 2
    # some block not marked done holds data: the one the kill interrupted
    half = [c for c in range(grid.chunks) if c not in done
            and (killed.branches.values[grid.region(c)] >= 0).any()]
    assert len(half) == 1
    before = {p: t for c in done for p, t in _block_files(store, grid, c).items()}
    computed = []
    ds = run_sweep("stability", STABILITY_AXES, store, scheduler=scheduler,
                   progress=lambda p: computed.append(p.chunk))
    assert set(computed) == set(range(grid.chunks)) - done and half[0] in computed
    assert {p: p.stat().st_mtime_ns for p in before} == before
    xr.testing.assert_identical(ds.load(), serial_sweep("stability", STABILITY_AXES, chunk=2))


def test_unanswering_scheduler_is_refused_within_10_s(tmp_path):
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"scheduler tcp://127\.0\.0\.1:1") as err:
        run_sweep("response", RESPONSE_AXES, tmp_path / "s.zarr", scheduler="tcp://127.0.0.1:1")
    assert time.perf_counter() - t0 < 10
    assert "\n" not in str(err.value)
    assert not (tmp_path / "s.zarr").exists()  # refused before the store was made


def test_a_worker_or_a_stranger_is_not_a_scheduler(scheduler, tmp_path):
    from distributed import Client

    with Client(scheduler, set_as_default=False) as client:
        worker = next(iter(client.scheduler_info()["workers"]))
    with pytest.raises(InputError, match="answers, but as Worker"):
        run_sweep("response", RESPONSE_AXES, tmp_path / "s.zarr", scheduler=worker)
    with pytest.raises(InputError, match="not an address"):
        run_sweep("response", RESPONSE_AXES, tmp_path / "s.zarr", scheduler="nonsense")
    assert list(tmp_path.iterdir()) == []


def test_store_of_another_sweep_is_refused(tmp_path):
    store = tmp_path / "s.zarr"
    run_sweep("stability", STABILITY_AXES, store, stop_after=0)  # metadata only, no cluster
    with pytest.raises(InputError, match="holds a stability sweep, not response"):
        run_sweep("response", STABILITY_AXES, store, scheduler="tcp://127.0.0.1:1")
    other = {**STABILITY_AXES, "omega": [0.9, 1.1]}
    with pytest.raises(InputError, match="axis omega differs"):
        run_sweep("stability", other, store, scheduler="tcp://127.0.0.1:1")
    with pytest.raises(InputError, match="chunk=12"):
        run_sweep("stability", STABILITY_AXES, store, chunk=5, scheduler="tcp://127.0.0.1:1")
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "a.txt").write_text("x")
    with pytest.raises(InputError, match="not a Zarr store"):
        run_sweep("stability", STABILITY_AXES, tmp_path / "notes")


@pytest.mark.parametrize("where", ["under_a_file", "proc", "missing_folder"])
def test_unwritable_store_is_refused_before_work(tmp_path, where):
    (tmp_path / "file").write_text("x")
    store = {"under_a_file": tmp_path / "file" / "s.zarr", "proc": Path("/proc/s.zarr"),
             "missing_folder": tmp_path / "no" / "s.zarr"}[where]
    with pytest.raises(InputError, match="store"):
        run_sweep("stability", STABILITY_AXES, store, scheduler="tcp://127.0.0.1:1")


def test_grid_too_large_for_the_disk_is_refused_before_work(tmp_path):
    axes = {"omega": list(np.linspace(0.5, 2, 10_000)), "force": list(np.linspace(0.1, 1, 1000)),
            "eps": list(np.linspace(0.01, 0.2, 1000)), "Q": [10.0, 20.0]}
    assert estimate_bytes(make_grid("response", axes)) > 1e12
    t0 = time.perf_counter()
    with pytest.raises(InputError, match="GB"):
        run_sweep("response", axes, tmp_path / "s.zarr", scheduler="tcp://127.0.0.1:1")
    assert time.perf_counter() - t0 < 5 and os.listdir(tmp_path) == []


@pytest.mark.parametrize(("kind", "axes", "chunk", "match"), [
    ("orbits", RESPONSE_AXES, None, "use one of response"),
    ("response", {"omega": [1.0]}, None, "missing force, eps, Q"),
    ("subharmonic", {**SUBHARMONIC_AXES, "Q": [20.0]}, None, "unknown Q"),
    ("response", {**RESPONSE_AXES, "Q": [0.0]}, None, "Q 0.0"),
    ("response", {**RESPONSE_AXES, "omega": [1.0, 1.0]}, None, "repeated"),
    ("response", {**RESPONSE_AXES, "omega": "1.0"}, None, "list of values"),
    ("response", RESPONSE_AXES, 0, "chunk"),
])
def test_bad_grids(kind, axes, chunk, match):
    with pytest.raises(InputError, match=match):
        make_grid(kind, axes, chunk)


def test_sweep_figure(tmp_path):
    ds = serial_sweep("response", RESPONSE_AXES)
    path = sweep_figure(ds, tmp_path / "r.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    partial = run_sweep("response", RESPONSE_AXES, tmp_path / "p.zarr", stop_after=0)
    with pytest.raises(InputError, match="0 of 1 blocks"):
        sweep_figure(partial, tmp_path / "p.png")


def test_cli_sweep_killed_then_resumed_equals_serial(tmp_path):
    """`lindstedt sweep` on its own LocalCluster, killed (with its workers) once some blocks
    are in the store, then the same command again: the store completes and equals the serial
    map point for point."""
    import zarr

    axes = {"omega": [1.0 + 0.6 * i / 11 for i in range(12)], "force": [0.3], "eps": [0.1],
            "Q": [20.0]}
    args = [sys.executable, "-m", "lindstedt", "sweep", "stability", "--omega", "1.0:1.6:12",
            "--force", "0.3", "--eps", "0.1", "--Q", "20", "--chunk", "4", "--out", "s",
            "--workers", "1", "--json"]
    # NOTE: one worker: its cluster is killed and a second started all the same, for half
    # the processes (test_local_cluster_equals_serial_and_shooting runs two)
    proc = subprocess.Popen(args, cwd=tmp_path, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 240
    finished = 0
    while time.monotonic() < deadline and proc.poll() is None:
        with contextlib.suppress(Exception):
            finished = int(np.asarray(zarr.open_group(str(tmp_path / "s"), mode="r")["done"]
                                      [...]).sum())
        if finished >= 1:
            break
        time.sleep(0.1)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    run = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=600,
                         check=False)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""  # dask's closing says nothing once the store is whole
    summary = json.loads(run.stdout)
    assert summary["complete"] and summary["finished"] == summary["blocks"] == 3
    resumed = open_sweep(tmp_path / "s")
    serial = serial_sweep("stability", axes, chunk=4)
    for name in ("orbits", "stable_orbits"):
        np.testing.assert_array_equal(resumed[name].values, serial[name].values)
    for name in ("max_floquet", "r"):  # the workers' single-threaded LAPACK: rounding apart
        np.testing.assert_allclose(resumed[name].values, serial[name].values, rtol=1e-12)


def test_stability_counts_every_distinct_orbit_against_dop853():
    """The stability map counts the orbits the one-harmonic roots miss: at ω = 1.491 (ε 0.1,
    f 0.3, Q 20) the cubic has one root and the true system three orbits (two stable), and
    inside the softening spring's fold window at ω = 0.804 (ε −0.1) likewise. Each count,
    the largest Floquet modulus and the small branch's r against DOP853 + Newton on the period
    map (test_branches), started from every orbit's state and from the one-harmonic root."""
    from lindstedt.analysis.periodic import periodic_orbits
    from test_branches import _cubic_seeds, _distance, reference_orbit

    for eps, w in ((EPS, 1.491), (-0.1, 0.804)):
        axes = {"omega": [w], "force": [FORCE], "eps": [eps], "Q": [Q]}
        point = serial_sweep("stability", axes).isel(omega=0, force=0, eps=0, Q=0)
        starts = [o.orbit.initial for o in periodic_orbits(Drive(eps, FORCE, w, Q)).orbits]
        refs = []
        for y0 in [*starts, *_cubic_seeds(eps, FORCE, w, 1 / Q)]:
            ref = reference_orbit(y0, eps, FORCE, w, 1 / Q)
            if ref is not None and all(_distance(ref[0], o[0], w) > 1e-7 for o in refs):
                refs.append(ref)
        assert len(refs) == 3 and int(point.branches) == 1
        assert int(point.orbits) == 3 and int(point.stable_orbits) == 2
        assert sum(ref[3] for ref in refs) == 2
        top = max(m for ref in refs for m in ref[2])
        assert abs(float(point.max_floquet) - top) < 1e-6
        (seed,) = _cubic_seeds(eps, FORCE, w, 1 / Q)  # the one root, and its orbit
        own = reference_orbit(seed, eps, FORCE, w, 1 / Q)
        assert abs(float(point.r[0]) - own[1]) < 1e-8 and int(point.orbit_stable[0]) == 1
        assert np.isnan(point.r[1:]).all()


# --- a user's equation: any parameter an axis ------------------------------------------------

SWEPT = "q'' + 0.05*q' + q + eps*(alpha*q**2 + q**3) = f*cos(w*t)"


def _attractor_from_rest(terms, force, omega, periods=240):
    """DOP853 from rest over ``periods`` drive periods (40/γ of transients and more), then r
    of the last period by FFT: the attractor a user meets."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        return [y[1], force * math.cos(omega * t)
                - sum(c * y[0] ** a * y[1] ** b for (a, b), c in terms.items())]

    T = 2 * math.pi / omega
    sol = solve_ivp(rhs, (0, periods * T), [0.0, 0.0], method="DOP853", rtol=1e-10,
                    atol=1e-12, dense_output=True)
    q = sol.sol((periods - 1) * T + np.arange(256) * T / 256)[0]
    return 2 * abs(np.fft.rfft(q)[1]) / 256


def test_equation_sweep_stable_r_is_the_attractor_dop853_reaches_from_rest():
    """``sweep response EQUATION --axis w=… --axis alpha=… --param eps=1/10 --param f=3/10``
    (serially here): at every point the steady state DOP853 reaches from rest is one of the
    stored stable orbits (its r within 1e-6), and a point with three orbits holds one unstable
    between two stable (the fold's hysteresis)."""
    kind = kind_of("response", SWEPT, {"eps": "1/10", "f": "3/10"}, ["w", "alpha"])
    ds = serial_sweep(kind, {"w": [0.9, 1.3, 1.5], "alpha": [0.0, 0.5]})
    assert ds["r"].dims == ("w", "alpha", "branch")
    for i, w in enumerate(ds["w"].values):
        for j, alpha in enumerate(ds["alpha"].values):
            terms = {(1, 0): 1.0, (0, 1): 0.05, (3, 0): 0.1, (2, 0): 0.1 * alpha}
            truth = _attractor_from_rest({k: v for k, v in terms.items() if v}, 0.3, w)
            r, stable = ds["r"].values[i, j], ds["stable"].values[i, j]
            kept = r[stable == 1]
            assert np.min(np.abs(kept - truth)) < 1e-6, (w, alpha, truth, r, stable)
    three = ds["orbits"].values == 3
    assert three.any()
    for index in zip(*np.nonzero(three), strict=True):
        assert list(ds["stable"].values[index][:3]) == [1, 0, 1]


def test_equation_subharmonic_sweep_against_the_command():
    """The subharmonic map of a quadratic force over its drive frequency: each point's orbits
    are the ``subharmonic EQUATION --n 2`` command's at that point."""
    from lindstedt.analysis.subharmonic import subharmonic_equation, subharmonic_orbits

    text = "x'' + 0.05*x' + x + x**2 = f*cos(W*t)"
    kind = kind_of("subharmonic", text, {"f": "1/2"}, ["W"], n=2)
    ds = serial_sweep(kind, {"W": [1.6, 2.0, 2.4]})
    for i, W in enumerate(ds["W"].values):
        found = subharmonic_orbits(subharmonic_equation(text, {"f": "1/2"}, W / 2, 2),
                                   onset=False)
        assert ds["exists"].values[i] == int(found.exists)
        rs = ds["r"].values[i]
        assert np.allclose(rs[: len(found.orbits)], [o.r for o in found.orbits], atol=1e-9)
    assert ds["exists"].values[1] == 1


SYSTEM = "x1'' + c*x1' + 2*x1 - x2 + k*x1**3 = f*cos(w*t); x2'' + c*x2' + 2*x2 - x1 = 0"


def test_system_sweep_linear_points_are_the_complex_amplitudes_exactly():
    """``sweep response SYSTEM --axis w=… --axis c=…`` with the cubic switched off (k = 0): one
    stable orbit at every point, its r = |(K − ω² + iωc)⁻¹F| (linear algebra, another route);
    with the cubic on, a point inside the fold (ω = 1.14, between the folds 1.1189 and 1.1648
    that test_response_system checks by shooting) holds two stable orbits around an unstable
    one."""
    kind = kind_of("response", SYSTEM, {"f": "1/10", "k": "0"}, ["w", "c"])
    ds = serial_sweep(kind, {"w": [0.7, 1.0, 1.5, 2.2], "c": [0.05, 0.2]})
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    for i, w in enumerate(ds["w"].values):
        for j, c in enumerate(ds["c"].values):
            X = np.linalg.solve(K - w**2 * np.eye(2) + 1j * w * c * np.eye(2), [0.1, 0.0])
            assert ds["orbits"].values[i, j] == 1 and ds["stable"].values[i, j, 0] == 1
            assert abs(ds["r"].values[i, j, 0] - np.linalg.norm(X)) < 1e-12
            assert abs(ds["r_x1"].values[i, j, 0] - abs(X[0])) < 1e-12
            assert abs(ds["r_x2"].values[i, j, 0] - abs(X[1])) < 1e-12
            assert ds["floquet"].values[i, j, 0] == pytest.approx(np.exp(-np.pi * c / w),
                                                                  rel=1e-8)
    hard = kind_of("response", SYSTEM, {"f": "3/10", "k": "1/2", "c": "1/20"}, ["w"])
    ds = serial_sweep(hard, {"w": [1.14]})
    assert ds["orbits"].values[0] == 3
    assert list(ds["stable"].values[0][:3]) == [1, 0, 1]


@pytest.mark.parametrize("argv, says", [
    (["--axis", "beta=0:1:3", "--param", "eps=1/10", "--param", "f=3/10", "--param",
      "alpha=1"], "beta: not a parameter"),
    (["--axis", "w=1:2:3", "--axis", "alpha=0:1:2", "--param", "alpha=1", "--param",
      "eps=1/10", "--param", "f=3/10"], "--axis alpha and --param alpha"),
    (["--axis", "w=1:2:3", "--param", "eps=1/10", "--param", "f=3/10"],
     "alpha: give it a value (--param alpha=...) or an axis"),
    (["--axis", "w=-1:2:3", "--param", "alpha=1", "--param", "eps=1/10", "--param",
      "f=3/10"], "axis w: the drive frequency must be > 0"),
    (["--omega", "1:2:3", "--param", "alpha=1"], "--omega: with an equation"),
])
def test_equation_sweep_refusals(tmp_path, capsys, argv, says):
    from lindstedt.cli import main

    store = tmp_path / "s"
    assert main(["sweep", "response", SWEPT, *argv, "--out", str(store)]) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and len(err.splitlines()) == 1, err
    assert not store.exists()


def test_one_table_says_which_problems_each_kind_takes():
    """:data:`sweep.kinds.KINDS`: every kind takes the notes' axes; response, stability and
    subharmonic a user's equation; response alone a system; each refusal in one line naming
    the kinds that do take it."""
    from lindstedt.derive.problem import read_problem
    from lindstedt.sweep.kinds import KINDS

    one, pair = read_problem(SWEPT), read_problem(SYSTEM)
    takes = {name: tuple(k.why_not(p) is None for p in (None, one, pair))
             for name, k in KINDS.items()}
    assert takes == {"response": (True, True, True), "stability": (True, True, False),
                     "subharmonic": (True, True, False), "validity": (True, False, False),
                     "ssm": (False, True, True)}
    assert "with an equation use response, stability, subharmonic" in \
        KINDS["validity"].why_not(one)
    assert "a system's map is response" in KINDS["stability"].why_not(pair)
    assert kind_of("stability").name == "stability" and kind_of("stability").builtin


def test_validity_takes_no_equation(tmp_path, capsys):
    from lindstedt.cli import main

    assert main(["sweep", "validity", SWEPT, "--axis", "w=1", "--out",
                 str(tmp_path / "s")]) == 2
    assert "the notes'" in capsys.readouterr().err


# --- faults: concurrent runs, too many workers, a full disk, a vanishing drive, dask's noise ----

def test_runs_racing_to_create_one_store_leave_it_whole(tmp_path):
    """Six threads make the same new store at once (metadata only, no cluster): each gets the
    store or the one-line "another sweep is writing it"; the store is whole (it opens and is
    this sweep's), and no temporary folder is left beside it."""
    import threading

    store = tmp_path / "s.zarr"
    outcomes, start = [], threading.Barrier(6)

    def run():
        start.wait()
        try:
            outcomes.append(run_sweep("response", RESPONSE_AXES, store, stop_after=0))
        except InputError as e:
            outcomes.append(str(e))

    threads = [threading.Thread(target=run) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(outcomes) == 6
    for o in outcomes:
        assert isinstance(o, xr.Dataset) or ("another sweep is writing it" in o
                                             and "\n" not in o), o
    assert os.listdir(tmp_path) == ["s.zarr"]
    ds = open_sweep(store)
    assert not ds.done.values.any() and ds.r.shape == (3, 2, 1, 1, 3)


def test_a_second_run_of_a_store_being_written_is_refused(scheduler, tmp_path):
    """While one run holds its store (made under a temporary name, renamed, locked), a second
    run — of the store it found, or racing to make it — stops in one line before any block;
    the first run's store then resumes to the serial map."""
    from lindstedt.sweep import store as sweep

    path = tmp_path / "s.zarr"
    grid = make_grid("response", RESPONSE_AXES, 2)
    with sweep._claimed(path, grid, True):
        assert os.listdir(tmp_path) == ["s.zarr"]
        with pytest.raises(InputError, match="another sweep is writing it") as err:
            run_sweep("response", RESPONSE_AXES, path, scheduler=scheduler, chunk=2)
        assert "\n" not in str(err.value)
        # a run that also found no store: its rename fails, it finds this one, locked
        with pytest.raises(InputError, match="another sweep is writing it"), \
                sweep._claimed(path, grid, True):
            pass
        assert os.listdir(tmp_path) == ["s.zarr"]
    ds = run_sweep("response", RESPONSE_AXES, path, scheduler=scheduler)
    xr.testing.assert_identical(ds.load(), serial_sweep("response", RESPONSE_AXES, chunk=2))


def test_workers_beyond_the_cores_are_cut_with_a_note(scheduler, tmp_path, capsys,
                                                     monkeypatch):
    """--workers 64 on a machine of 2 usable cores runs 2 (the cost estimate counts 2), with
    one line on stderr; the library cuts likewise; the core count is the affinity's."""
    import lindstedt.cli.sweep as cli_sweep
    from lindstedt.cli import build_parser, main
    from lindstedt.costs import sweep_cost
    from lindstedt.sweep import store as sweep
    from lindstedt.sweep.cores import usable_cores

    if hasattr(os, "sched_getaffinity"):
        assert usable_cores() == len(os.sched_getaffinity(0))
    monkeypatch.setattr(cli_sweep, "usable_cores", lambda: 2)
    argv = ["sweep", "response", "--omega", "0.7,1.2", "--force", "0.3", "--eps", "0.1",
            "--Q", "20", "--out", str(tmp_path / "s.zarr")]
    args = build_parser().parse_args([*argv, "--workers", "64"])
    assert (args.workers, args.workers_asked) == (2, 64)
    two = build_parser().parse_args([*argv, "--workers", "2"])
    assert sweep_cost(args).seconds == sweep_cost(two).seconds
    run_sweep("response", {**RESPONSE_AXES, "omega": [0.7, 1.2], "force": [0.3]},
              tmp_path / "s.zarr", scheduler=scheduler)  # complete: the command starts no cluster
    assert main([*argv, "--workers", "64"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["lindstedt: note: --workers 64: 2 cores here; running 2 workers"]
    asked = []

    def cluster(workers):
        asked.append(workers)
        raise InputError("no cluster in this test")

    monkeypatch.setattr(sweep, "usable_cores", lambda: 3)
    monkeypatch.setattr(sweep, "local_cluster", cluster)
    with pytest.raises(InputError, match="no cluster"):
        run_sweep("response", RESPONSE_AXES, tmp_path / "t.zarr", workers=64)
    assert asked == [3]


def test_a_full_disk_ends_in_one_line_and_the_store_resumes(scheduler, tmp_path, capsys,
                                                           monkeypatch):
    """ENOSPC on the third block's write: the command prints one line naming the store, the
    error and how to resume, exit 2; the two blocks saved stay, the rest resumes to the serial
    map. EACCES making a new store leaves nothing behind."""
    import errno

    from lindstedt.cli import main
    from lindstedt.sweep import store as sweep

    path = tmp_path / "s.zarr"
    write, calls = sweep._write_block, []

    def full(arrays, grid, chunk, data):
        calls.append(chunk)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path / "r" / "c"))
        write(arrays, grid, chunk, data)

    monkeypatch.setattr(sweep, "_write_block", full)
    argv = ["sweep", "response", "--omega", "0.7,1.2,1.5", "--force", "0.1,0.3", "--eps",
            "0.1", "--Q", "20", "--chunk", "1", "--out", str(path), "--scheduler", scheduler,
            "--json"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1, err
    assert f"store {path}: cannot write (No space left on device); 2/6 blocks saved" in err
    assert "run the same command to resume" in err
    assert int(open_sweep(path).done.values.sum()) == 2
    assert not list(path.rglob("*.partial"))
    monkeypatch.setattr(sweep, "_write_block", write)
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["complete"]
    xr.testing.assert_identical(open_sweep(path).load(),
                                serial_sweep("response", RESPONSE_AXES, chunk=1))

    def denied(path, grid):
        raise OSError(errno.EACCES, os.strerror(errno.EACCES), str(path))

    monkeypatch.setattr(sweep, "_write_metadata", denied)
    with pytest.raises(InputError, match=r"t\.zarr: cannot write \(Permission denied\)"):
        run_sweep("response", RESPONSE_AXES, tmp_path / "t.zarr", stop_after=0)
    assert sorted(os.listdir(tmp_path)) == ["s.zarr"]


def test_a_vanishing_drive_is_the_rest_state_of_the_damped_system(scheduler, tmp_path, capsys):
    """``--axis f=0:1/10:3``: at f = 0 the response is the rest state, r = 0 on every
    coordinate, one stable orbit, its Floquet modulus exp(−πc/ω) (C = cI: every mode decays as
    e^{−ct/2}), the limit of the points at f → 0; the scalar equation likewise. A point the
    equation is refused at (c = 0: no steady state) is noted by the command."""
    from lindstedt.cli import main

    kind = kind_of("response", SYSTEM, {"c": "1/20", "k": "1/2"}, ["f", "w"])
    ds = serial_sweep(kind, {"f": [0.0, 1e-7, 0.05], "w": [1.0, 1.7]})
    for j, w in enumerate([1.0, 1.7]):
        rest = ds.isel(f=0, w=j)
        assert int(rest.orbits) == 1 and int(rest.stable_orbits) == 1
        for name in ("r", "r_x1", "r_x2"):
            assert float(rest[name][0]) == 0.0 and np.isnan(rest[name][1:]).all()
        assert int(rest.stable[0]) == 1 and float(rest.r_stable_max) == 0.0
        assert float(rest.floquet[0]) == pytest.approx(math.exp(-math.pi * 0.05 / w), rel=1e-12)
        assert float(ds.floquet.isel(f=1, w=j, branch=0)) == pytest.approx(
            float(rest.floquet[0]), rel=1e-6)
        assert 0 < float(ds.r.isel(f=1, w=j, branch=0)) < 1e-5
    scalar = kind_of("response", SWEPT, {"eps": "1/10", "alpha": "0"}, ["f", "w"])
    one = serial_sweep(scalar, {"f": [0.0], "w": [0.8]}).isel(f=0, w=0)
    assert int(one.orbits) == 1 and float(one.r[0]) == 0.0 and int(one.stable[0]) == 1
    assert float(one.floquet[0]) == pytest.approx(math.exp(-math.pi * 0.05 / 0.8), rel=1e-12)
    store = tmp_path / "c.zarr"
    assert main(["sweep", "response", SYSTEM, "--axis", "c=0,1/20", "--param", "f=1/10",
                 "--param", "k=0", "--axis", "w=1", "--out", str(store), "--scheduler",
                 scheduler]) == 0
    out = capsys.readouterr().out
    assert "note: 1 of 2 points hold no orbit (orbits = -1)" in out and "first at c = 0" in out
    ds = open_sweep(store)
    assert ds.orbits.values.tolist() == [[-1], [1]]
    assert "refused" in ds.orbits.attrs["comment"]


def test_dask_noise_of_a_whole_run_stays_off_stderr(scheduler, tmp_path):
    """What distributed logs during a run whose store ends whole (a worker's result gathered
    again, comms closing) reaches no handler; in a run that fails, it does."""
    import logging

    class Collect(logging.Handler):
        def __init__(self):
            super().__init__(logging.ERROR)
            self.seen = []

        def emit(self, record):
            self.seen.append(record.getMessage())

    log, top, collect = logging.getLogger("distributed.scheduler"), logging.getLogger(
        "distributed"), Collect()
    top.addHandler(collect)  # beside distributed's own StreamHandler to stderr

    def noisy(p):
        log.error("Couldn't gather keys: {'x': 'memory'} (test)")

    try:
        ds = run_sweep("response", RESPONSE_AXES, tmp_path / "a.zarr", scheduler=scheduler,
                       chunk=2, progress=noisy)
        assert bool(ds.done.values.all()) and collect.seen == []

        def failing(p):
            noisy(p)
            raise RuntimeError("a bug in the caller")

        with pytest.raises(RuntimeError, match="a bug"):
            run_sweep("response", RESPONSE_AXES, tmp_path / "b.zarr", scheduler=scheduler,
                      chunk=2, progress=failing)
        assert "Couldn't gather keys: {'x': 'memory'} (test)" in collect.seen
        assert all(not h.filters for h in top.handlers)
    finally:
        top.removeHandler(collect)
