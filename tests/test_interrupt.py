"""Ctrl-C and SIGTERM: a long command stops at once with one line (what was saved, how to
resume), exit status 130, no traceback, nothing half-written; a sweep resumes where it stopped
and ends with the values of an uninterrupted run."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

LINDSTEDT = [sys.executable, "-m", "lindstedt"]
GRID = ["stability", "--omega", "0.5:2:30", "--force", "0.3", "--eps", "0.1", "--Q", "20",
        "--chunk", "10"]


def _start(args: list[str]) -> subprocess.Popen:
    """The command in a session of its own, as a terminal runs a foreground job."""
    return subprocess.Popen([*LINDSTEDT, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)


def _blocks_done(store: Path) -> int:
    """The blocks whose ``done`` flag is on disk (each block writes its data, then its flag
    chunk): the files of the ``done`` array's chunks, zarr's temporaries left out."""
    chunks = store / "done" / "c"
    if not chunks.is_dir():
        return 0
    return sum(1 for f in chunks.rglob("*") if f.is_file() and not f.name.endswith(".partial"))


def _stop(p: subprocess.Popen, how: str) -> tuple[int, str, float]:
    start = time.monotonic()
    if how == "ctrl-c":
        os.killpg(p.pid, signal.SIGINT)  # a terminal's Ctrl-C reaches the whole group
    else:
        p.send_signal(signal.SIGTERM)  # `kill PID`: the command alone
    _, err = p.communicate(timeout=60)
    return p.returncode, err, time.monotonic() - start


def _workers_left(pid: int) -> list[str]:
    out = subprocess.run(["ps", "-o", "pid=,ppid=,args=", "-e"], capture_output=True,
                         text=True).stdout
    return [line for line in out.splitlines() if f" {pid} " in f" {line.split(None, 2)[1]} "]


@pytest.mark.parametrize("how", ["ctrl-c", "sigterm"])
def test_an_interrupted_sweep_says_what_it_saved_and_resumes(how, tmp_path):
    store = tmp_path / "map.zarr"
    p = _start(["sweep", *GRID, "--out", str(store), "--workers", "1"])  # ~1 s a block of 10
    deadline = time.monotonic() + 120
    while _blocks_done(store) < 1:
        assert p.poll() is None, p.communicate()
        assert time.monotonic() < deadline, "no block written in 2 minutes"
        time.sleep(0.1)
    status, err, took = _stop(p, how)
    assert status == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lindstedt: interrupted: "), err
    assert f"blocks saved in {store}; run the same command to resume" in lines[0]
    saved, total = (int(v) for v in lines[0].split(": ")[2].split()[0].split("/"))
    assert 1 <= saved < total == 3
    assert took < 3.0, took  # at once (a second is the aim; the machine may be loaded)
    with xr.open_zarr(store) as ds:
        assert int(ds["done"].values.sum()) == saved
    time.sleep(0.5)
    assert not _workers_left(p.pid)  # the workers went with it
    resumed = subprocess.run([*LINDSTEDT, "sweep", *GRID, "--out", str(store), "--workers", "1",
                              "--json"],
                             capture_output=True, text=True, check=True)
    assert '"complete": true' in resumed.stdout
    if how != "ctrl-c":
        return
    from lindstedt.sweep.store import serial_sweep

    with xr.open_zarr(store) as a:  # against the same map computed in one go, in this process
        b = serial_sweep("stability", {name: a[name].values for name in a["orbits"].dims})
        for name in ("orbits", "stable_orbits", "r", "floquet"):
            assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name


def test_an_interrupted_generate_writes_nothing(tmp_path):
    out = tmp_path / "gen"
    p = _start(["generate", "q'' + q + eps*(alpha*q**2 + q**3) = 0", "--order", "90",
                "--out", str(out), "--allow-slow"])
    time.sleep(4.0)
    assert p.poll() is None, p.communicate()
    status, err, took = _stop(p, "sigterm")
    assert status == 130, err
    assert err.strip() == ("lindstedt: interrupted: stopped before the end; no file is left "
                           "half-written")
    assert took < 3.0, took
    assert not out.exists() or not any(out.iterdir())
