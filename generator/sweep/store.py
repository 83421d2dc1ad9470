"""Sweeps of a kind over a grid, into a resumable Zarr store, on dask.distributed.

The grid is cut into rectangular blocks (contiguous in C order, aligned with the Zarr chunks).
Each block is one task on ``dask.distributed`` — a :class:`~distributed.LocalCluster` of
single-threaded worker processes by default, or an existing scheduler — and the client writes
each finished block into a Zarr store (into the block's region of a store whose metadata
``to_zarr(compute=False)`` wrote first), then that block's ``done`` flag. Zarr's local store
writes each chunk file atomically, so a flag is never half-written, and a block whose data was
written but whose flag was not is simply computed again: an interrupted sweep resumes where
it stopped. A new store is made whole under a temporary name and renamed into place, and a
run holds an exclusive lock (``flock``) on its store's folder while it writes: two runs of
one store never write it at once, and no store is ever left half-made. :func:`serial_sweep`
computes the same map in this process, block by block, without dask: the reference and the
baseline.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import itertools
import json
import logging
import math
import os
import shutil
import socket
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..analysis.driven import Drive
from ..errors import InputError, Interrupted
from ..limits import MAX_WORKERS, check_int
from .cores import usable_cores

if TYPE_CHECKING:
    import xarray as xr

# NOTE: xarray and zarr are imported where the client uses them: every worker imports this
# module to run its blocks and needs neither (~1.3 s of each worker's start-up, measured).

from .kinds import Kind, WarmUp, compute_block, kind_named

# --- the grid and its blocks ---------------------------------------------------------------------

FORMAT = 1
# NOTE: the layout version in every store's identity: a store of another layout is refused.


@dataclass(frozen=True)
class Grid:
    """The axes of one sweep (in the kind's order) and the block each task computes."""

    kind: Kind
    values: tuple[np.ndarray, ...]
    block: tuple[int, ...]

    @property
    def shape(self) -> tuple[int, ...]:
        """The number of values along each axis."""
        return tuple(v.size for v in self.values)

    @property
    def points(self) -> int:
        """The number of grid points."""
        return math.prod(self.shape)

    @property
    def blocks(self) -> tuple[int, ...]:
        """Blocks along each axis."""
        return tuple(-(-n // b) for n, b in zip(self.shape, self.block, strict=True))

    @property
    def chunks(self) -> int:
        """The number of blocks: one task each."""
        return math.prod(self.blocks)

    def region(self, chunk: int) -> tuple[slice, ...]:
        """The index slices of block number ``chunk`` (C order over :attr:`blocks`)."""
        out = []
        for n, b, nb in reversed(list(zip(self.shape, self.block, self.blocks, strict=True))):
            chunk, k = divmod(chunk, nb)
            out.append(slice(k * b, min((k + 1) * b, n)))
        return tuple(reversed(out))

    def block_values(self, chunk: int) -> tuple[np.ndarray, ...]:
        """The axis values of block number ``chunk``, one array per axis."""
        return tuple(v[s] for v, s in zip(self.values, self.region(chunk), strict=True))

    def identity(self) -> dict:
        """What a store must match to be resumed: kind, axes, blocks, settings, layout."""
        return {"format": FORMAT, "kind": self.kind.name,
                "axes": {a: [float(x) for x in v]
                         for a, v in zip(self.kind.axes, self.values, strict=True)},
                "block": list(self.block), "settings": dict(self.kind.settings)}


def block_shape(shape: Sequence[int], points: int) -> tuple[int, ...]:
    """Blocks of at most ``points`` points that are contiguous in C order: whole trailing axes
    while they fit, then a slab of the next axis, one index of the axes before it."""
    block = [1] * len(shape)
    size = 1
    for k in reversed(range(len(shape))):
        if size * shape[k] <= points:
            block[k], size = shape[k], size * shape[k]
        else:
            block[k] = max(1, points // size)
            break
    return tuple(block)


_PROBE = {"eps": 0.1, "force": 1.0, "omega": 1.0, "Q": math.inf}
# NOTE: a valid drive each axis value is checked against, one field at a time.


def _axis(name: str, values: object, builtin: bool = True) -> np.ndarray:
    """One axis as float64, each value checked by :class:`Drive`'s rules (finite, ω > 0,
    Q > 0 or inf) on a built-in kind, finite on an equation's (whose own parse checks the
    rest, point by point), no repeats."""
    if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)):
        raise InputError(f"axis {name}: give a list of values, not {values!r}")
    out = []
    for v in values:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, Real):
            raise InputError(f"axis {name}: {v!r} is not a number")
        if builtin:
            Drive(**{**_PROBE, name: float(v)})
        elif not math.isfinite(float(v)):
            raise InputError(f"axis {name}: {v!r} is not finite")
        out.append(float(v))
    if not out:
        raise InputError(f"axis {name}: no values")
    arr = np.array(out)
    if np.unique(arr).size != arr.size:
        raise InputError(f"axis {name}: repeated values")
    return arr


def make_grid(kind: str | Kind, axes: Mapping[str, Sequence[float]],
              chunk: int | None = None) -> Grid:
    """The checked grid of ``kind`` over ``axes`` (exactly the kind's axes, each a list of
    values) in blocks of at most ``chunk`` points (default: the kind's, ~1 s of work)."""
    kind = kind if isinstance(kind, Kind) else kind_named(kind)
    if not isinstance(axes, Mapping):
        raise InputError(f"sweep axes: give a mapping of axis name to values, not {axes!r}")
    missing = [a for a in kind.axes if a not in axes]
    unknown = [a for a in axes if a not in kind.axes]
    if missing or unknown:
        what = "; ".join(part for part in (
            missing and f"missing {', '.join(missing)}",
            unknown and f"unknown {', '.join(map(str, unknown))}") if part)
        raise InputError(f"sweep {kind.name}: axes {what} (it takes {', '.join(kind.axes)})")
    values = tuple(_axis(a, axes[a], kind.builtin) for a in kind.axes)
    if kind.positive:
        for a, v in zip(kind.axes, values, strict=True):
            if a in kind.positive and not np.all(v > 0):
                raise InputError(f"axis {a}: the drive frequency must be > 0")
    points = kind.points_per_chunk if chunk is None else chunk
    check_int(points, 1, None, f"chunk {chunk!r}: must be a whole number of points >= 1")
    return Grid(kind, values, block_shape([v.size for v in values], points))


# --- the dataset and its store -------------------------------------------------------------------

def _dataset(grid: Grid, data: Mapping[str, np.ndarray] | None, done: np.ndarray | None
             ) -> xr.Dataset:
    """The sweep's Dataset: ``data`` given, in memory; else lazy fill arrays chunked like the
    blocks (a template whose ``to_zarr(compute=False)`` writes only metadata and coordinates)."""
    import dask.array as da
    import xarray as xr

    kind = grid.kind
    sizes = kind.extra_sizes
    coords = {a: (a, v) for a, v in zip(kind.axes, grid.values, strict=True)}
    coords |= {dim: (dim, np.array(values)) for dim, values in kind.extra}
    variables = {}
    for f in kind.fields:
        dims = (*kind.axes, *f.dims)
        if data is None:
            shape = grid.shape + tuple(sizes[d] for d in f.dims)
            array = da.full(shape, f.fill, dtype=f.dtype,
                            chunks=grid.block + tuple(sizes[d] for d in f.dims))
        else:
            array = data[f.name]
        variables[f.name] = xr.Variable(dims, array, f.attrs())
    variables["done"] = xr.Variable(
        ("chunk",), da.zeros(grid.chunks, dtype=bool, chunks=1) if done is None else done,
        {"long_name": "block finished: its data is written (C order over the blocks)"})
    return xr.Dataset(variables, coords, attrs={
        "kind": kind.name, "title": kind.description, "headline": kind.headline,
        "sweep": json.dumps(grid.identity())})


def _encoding(grid: Grid) -> dict:
    sizes = grid.kind.extra_sizes
    enc = {f.name: {"chunks": grid.block + tuple(sizes[d] for d in f.dims),
                    "fill_value": f.fill} for f in grid.kind.fields}
    # one flag per Zarr chunk: each is its own file, written atomically after its block
    enc["done"] = {"chunks": (1,), "fill_value": False}
    return enc


FS_BLOCK = 4096
# NOTE: every Zarr chunk is a file; a file takes whole 4 KiB blocks on ext4 and xfs.
METADATA_BYTES = 1 << 20
# NOTE: the zarr.json files and coordinate arrays: a few KiB; 1 MiB is a generous bound.


def estimate_bytes(grid: Grid, chunks: int | None = None) -> int:
    """Disk a store needs for ``chunks`` blocks (default all): every field uncompressed (NaN
    and random doubles barely compress), each chunk file rounded up to :data:`FS_BLOCK`."""
    sizes = grid.kind.extra_sizes
    per_block = math.prod(grid.block)
    per_chunk = FS_BLOCK  # the done flag
    for f in grid.kind.fields:
        nbytes = per_block * math.prod(sizes[d] for d in f.dims) * np.dtype(f.dtype).itemsize
        per_chunk += -(-nbytes // FS_BLOCK) * FS_BLOCK
    coords = 8 * sum(grid.shape)
    return (grid.chunks if chunks is None else chunks) * per_chunk + coords + METADATA_BYTES


def _probe_writable(folder: Path, what: str) -> None:
    """Create and remove a file in ``folder`` (``os.access`` says yes to root on read-only
    mounts and says nothing about a full disk)."""
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".lindstedt-probe-")
        os.close(fd)
        os.unlink(tmp)
    except OSError as e:
        raise InputError(f"store {what}: cannot write in {folder} ({e.strerror})") from None


def _stored_identity(path: Path) -> dict:
    """The identity a sweep's store carries (its ``sweep`` attribute), or :class:`InputError`
    for anything that is not such a store."""
    import zarr

    try:
        attrs = zarr.open_group(str(path), mode="r").attrs
    except Exception:  # zarr raises several kinds here: the message is ours
        raise InputError(f"store {path}: exists and is not a Zarr store (and not empty): "
                         "give a new path") from None
    if "sweep" not in attrs:
        raise InputError(f"store {path}: a Zarr store, but not a lindstedt sweep")
    return json.loads(attrs["sweep"])


def _adopt_block(path: Path, grid: Grid) -> Grid:
    """``grid`` in the blocks of the sweep stored at ``path``, when there is one over the same
    axes (anything else is left for :func:`check_store` to judge)."""
    import zarr

    try:
        stored = json.loads(zarr.open_group(str(path), mode="r").attrs["sweep"])
        block = tuple(int(b) for b in stored["block"])
    except Exception:  # no store, not a sweep: check_store says which
        return grid
    if len(block) != len(grid.shape) or any(b < 1 for b in block):
        return grid
    return replace(grid, block=block)


def _mismatch(path: Path, stored: dict, grid: Grid) -> str | None:
    """What differs between a store's identity and this sweep's, in words (None: nothing)."""
    asked = grid.identity()
    if stored.get("format") != asked["format"]:
        return f"store {path}: layout {stored.get('format')}, this version writes {FORMAT}"
    if stored["kind"] != asked["kind"]:
        return f"store {path}: holds a {stored['kind']} sweep, not {asked['kind']}"
    for axis in sorted(set(stored["axes"]) | set(asked["axes"])):
        a, b = stored["axes"].get(axis), asked["axes"].get(axis)
        if a != b:
            def show(v: list | None) -> str:
                return "none" if v is None else f"{len(v)} values {min(v):g}..{max(v):g}"
            return f"store {path}: axis {axis} differs (stored {show(a)}, asked {show(b)})"
    if stored["settings"] != asked["settings"]:
        return (f"store {path}: made with settings {stored['settings']}, this version uses "
                f"{asked['settings']}")
    if stored["block"] != asked["block"]:
        return (f"store {path}: made in blocks of {stored['block']} points; resume with "
                f"chunk={math.prod(stored['block'])} or without chunk")
    return None


@dataclass(frozen=True)
class StoreState:
    """A checked store: where, and which blocks are already done (``None``: a new store)."""

    path: Path
    done: np.ndarray | None


def check_store(store: Path | str, grid: Grid) -> StoreState:
    """Refuse, before any work, a store that is not this sweep's, that cannot be written, or
    whose disk cannot hold what is left to compute; else report the finished blocks."""
    import zarr

    path = Path(store)
    done = None
    if path.exists():
        if not path.is_dir():
            raise InputError(f"store {path}: exists and is not a directory")
        if any(path.iterdir()):
            problem = _mismatch(path, _stored_identity(path), grid)
            if problem:
                raise InputError(f"{problem}; give a new store path or delete it")
            done = np.asarray(zarr.open_array(str(path / "done"), mode="r")[:], dtype=bool)
        folder = path
    else:
        folder = path.parent if str(path.parent) else Path(".")
        if not folder.is_dir():
            raise InputError(f"store {path}: folder {folder} does not exist")
    _probe_writable(folder, str(path))
    left = grid.chunks - (0 if done is None else int(done.sum()))
    need, free = estimate_bytes(grid, left), shutil.disk_usage(folder).free
    if need > free:
        raise InputError(f"store {path}: the sweep needs ~{need / 1e9:.3g} GB "
                         f"({grid.points} points), {folder} has {free / 1e9:.3g} GB free")
    return StoreState(path, done)


@dataclass(frozen=True)
class _Arrays:
    """The Zarr arrays of an initialised store, opened once for a run's writes."""

    fields: Mapping[str, object]  # field name -> zarr.Array
    done: object  # zarr.Array of the flags


def _open_arrays(path: Path, grid: Grid) -> _Arrays:
    import zarr

    group = zarr.open_group(str(path), mode="r+")
    return _Arrays({f.name: group[f.name] for f in grid.kind.fields}, group["done"])


def _write_block(arrays: _Arrays, grid: Grid, chunk: int,
                 data: Mapping[str, np.ndarray]) -> None:
    """The block's data into its region: whole Zarr chunks, so nothing else is touched (zarr
    directly: a third of the cost of xarray's ``region=`` writes, which re-open and check the
    store every call; the client shares the cores with the workers)."""
    region = grid.region(chunk)
    for name, array in arrays.fields.items():
        array[region] = data[name]


def _mark_done(arrays: _Arrays, chunk: int) -> None:
    """The block's flag, written only after its data (its own chunk file, atomic)."""
    arrays.done[chunk] = True


def open_sweep(store: Path | str) -> xr.Dataset:
    """A sweep's store as a Dataset (lazily read, no dask); ``done`` says which blocks are.
    The metadata is consolidated when the store is made (blocks never change it), so
    ``xarray.open_zarr(path)`` reads it in one file, without a warning."""
    import xarray as xr

    path = Path(store)
    _stored_identity(path)
    return xr.open_zarr(str(path), consolidated=None, chunks=None)


# --- running ------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SweepProgress:
    """Reported after each block is written: which, and how many of all are done."""

    chunk: int
    finished: int  # blocks done in the store, earlier runs included
    total: int
    seconds: float  # since this run started computing


SCHEDULER_TIMEOUT = 4.0
# NOTE: a live scheduler answers a TCP connect in milliseconds and the handshake in well under
# a second; two such waits (connect, then the client's handshake) stay inside 10 s.


def _first_line(e: BaseException) -> str:
    return (str(e).splitlines() or [type(e).__name__])[0]


async def _identity(address: str) -> object:
    """distributed's handshake and an ``identity`` call: what answers at ``address``."""
    from distributed.comm import connect

    comm = await connect(address, timeout=SCHEDULER_TIMEOUT)
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        await comm.close()


def _probe_scheduler(address: str) -> None:
    """Ask ``address`` what it is before a client is made (a client that fails half-way
    lingers and stalls the interpreter's exit): a TCP connect for ``tcp://``/``tls://``, then
    the handshake and ``identity``, within :data:`SCHEDULER_TIMEOUT` in all. In a thread:
    ``getaddrinfo`` takes no timeout, and the caller may be inside an event loop."""
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        host_port = parse_host_port(location) if scheme in ("tcp", "tls") else None
    except (ValueError, TypeError) as e:
        raise InputError(f"scheduler {address}: not an address ({e})") from None
    answer: list = []
    failure: list[str] = []

    def ask() -> None:
        try:
            if host_port is not None:
                socket.create_connection(host_port, timeout=SCHEDULER_TIMEOUT).close()
            answer.append(asyncio.run(asyncio.wait_for(_identity(address), SCHEDULER_TIMEOUT)))
        except TimeoutError:
            failure.append(f"no answer within {SCHEDULER_TIMEOUT:g} s")
        except OSError as e:  # refused, unreachable, unknown host
            failure.append(e.strerror or _first_line(e))
        except Exception as e:  # a stranger's bytes can fail to decode in any way
            failure.append(f"no dask scheduler answers ({_first_line(e)})")

    probe = threading.Thread(target=ask, daemon=True)
    probe.start()
    probe.join(SCHEDULER_TIMEOUT)
    if probe.is_alive():
        failure.append(f"no answer within {SCHEDULER_TIMEOUT:g} s")
    if failure:
        raise InputError(f"scheduler {address}: {failure[0]}")
    kind = answer[0].get("type") if isinstance(answer[0], dict) else None
    if kind != "Scheduler":
        raise InputError(f"scheduler {address}: answers, but as {kind or 'something else'}, "
                         "not a dask scheduler")


QUIET = {"distributed.worker.profile.enabled": False,
         "distributed.admin.tick.interval": "1s",
         "distributed.admin.system-monitor.interval": "5s",
         "distributed.admin.system-monitor.gil.enabled": False,
         "distributed.worker.memory.monitor-interval": "1s"}
# NOTE: what a dashboard needs and a sweep does not: each worker samples its stacks every 10 ms
# for the profile, every process checks its event loop every 20 ms and its memory every 0.1 s.
# A 2-worker LocalCluster idles at 18 % of a core with them (client 7.7 %, workers 5 % each)
# and 2.4 % without (measured): on two cores that is CPU taken from the workers.


QUIET_TRACKER = "ignore:resource_tracker:UserWarning"
# NOTE: multiprocessing's resource tracker, a process of its own, unlinks the semaphores of an
# interrupted sweep (its workers stopped at once) and warns of each "leaked" one on stderr after
# the command's one line; it starts with this interpreter's -W options, so it does its work
# without the warning.


LOCAL_HTTP = "127.0.0.1:0"
# NOTE: the scheduler serves its HTTP routes even without a dashboard, by default on :8787 of
# every interface; a second sweep on the machine then warned "Port 8787 is already in use" on
# stderr. A free port of the loopback interface: no clash, nothing served beyond the machine.


def local_cluster(workers: int) -> object:
    """A LocalCluster of ``workers`` single-threaded processes, no dashboard, monitors quiet
    (:data:`QUIET`; the nannies hand the configuration to the workers they start)."""
    import dask
    from distributed import LocalCluster

    if QUIET_TRACKER not in sys.warnoptions:  # read when multiprocessing starts its tracker
        sys.warnoptions.append(QUIET_TRACKER)
    with dask.config.set(QUIET), _sigint_ignored():
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=LOCAL_HTTP, silence_logs=logging.ERROR)


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    """SIGINT ignored while the workers start, so that they inherit it ignored: Ctrl-C at a
    terminal reaches the whole process group, and the workers' own KeyboardInterrupt
    tracebacks would bury the command's one line (the command stops them itself)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def _connect(scheduler: str | None, workers: int, stack: contextlib.ExitStack) -> object:
    """A client: to ``scheduler``, or to a new :func:`local_cluster` of ``workers`` (closed
    with ``stack``)."""
    from distributed import Client

    if scheduler is None:
        cluster = stack.enter_context(local_cluster(workers))
        return stack.enter_context(Client(cluster, set_as_default=False))
    _probe_scheduler(scheduler)
    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT, set_as_default=False)
    except Exception as e:  # it answered the probe a moment ago: OSError, TimeoutError, …
        raise InputError(f"scheduler {scheduler}: no dask scheduler answers "
                         f"({_first_line(e)})") from None
    return stack.enter_context(client)


@dataclass(frozen=True)
class SweepSummary:
    """What a sweep's store holds, for the command to print: its axes (name, values) in the
    grid's order, its fields, its blocks and how many are finished; an equation's points that
    its finished blocks hold no orbit count for (``orbits`` −1: the equation is refused there,
    e.g. a damping axis at 0) and the first of them."""

    axes: tuple[tuple[str, tuple[float, ...]], ...]
    fields: tuple[str, ...]
    blocks: int
    finished: int
    refused: int = 0
    first_refused: tuple[tuple[str, float], ...] = ()

    @property
    def complete(self) -> bool:
        """Every block computed."""
        return self.finished == self.blocks


def summary(ds: xr.Dataset) -> SweepSummary:
    """The :class:`SweepSummary` of a sweep's dataset (:func:`run_sweep`'s answer)."""
    done = ds["done"].values
    identity = json.loads(ds.attrs["sweep"])
    names = list(identity["axes"])
    refused, first = 0, ()
    if "orbits" in ds.data_vars:  # an equation's map: −1 in a finished block is a refusal
        shape, block = ds["orbits"].shape, identity["block"]
        finished = done.reshape([-(-n // b) for n, b in zip(shape, block, strict=True)])
        for axis, b in enumerate(block):
            finished = np.repeat(finished, b, axis=axis)
        bad = finished[tuple(slice(0, n) for n in shape)] & (ds["orbits"].values == -1)
        refused = int(bad.sum())
        if refused:
            first = tuple((n, float(ds[n].values[i]))
                          for n, i in zip(names, np.argwhere(bad)[0], strict=True))
    return SweepSummary(tuple((n, tuple(float(v) for v in ds[n].values)) for n in names),
                        tuple(sorted(n for n in ds.data_vars if n != "done")),
                        int(done.size), int(done.sum()), refused, first)


def run_sweep(kind: str | Kind, axes: Mapping[str, Sequence[float]], store: Path | str,
              scheduler: str | None = None, workers: int = 2, chunk: int | None = None,
              progress: Callable[[SweepProgress], None] | None = None,
              stop_after: int | None = None) -> xr.Dataset:
    """Map ``kind`` over the grid ``axes`` on dask.distributed into the Zarr store ``store``.

    ``scheduler``: an address (``tcp://host:port``) of a running scheduler whose workers can
    import lindstedt (blocks wait until it has some); ``None`` starts a :func:`local_cluster` of
    ``workers`` processes, one thread each, at most
    :func:`~lindstedt.sweep.cores.usable_cores` (more single-threaded workers than cores only
    share them, at ~50 MB each; ``workers`` is ignored with a scheduler). ``chunk``: points
    per task (default the kind's, ~1 s of work; resuming, the store's).
    A store of this sweep resumes: only blocks without their ``done`` flag are computed.
    ``stop_after``: write at most this many blocks in this run, then stop (the store resumes
    later). ``progress`` is called after each block is written.

    Refused with :class:`InputError` before any work: a bad kind, axis or chunk; a store of
    another sweep or that cannot be written or whose disk is too small; a scheduler that does
    not answer (within ~2 × :data:`SCHEDULER_TIMEOUT`); a store another run is writing (each
    run locks its store). An OSError writing the store (a full disk, …) stops the run with
    :class:`StoreWriteError`: every block saved so far stays, and the store resumes. Returns
    :func:`open_sweep` of the store.
    """
    grid = make_grid(kind, axes, chunk)
    if scheduler is None:
        check_int(workers, 1, MAX_WORKERS,
                  f"workers {workers!r}: must be a whole number in 1..{MAX_WORKERS}")
        workers = min(workers, usable_cores())
    if stop_after is not None:
        check_int(stop_after, 0, None, f"stop_after {stop_after!r}: must be a whole number >= 0")
    if chunk is None:  # resuming without chunk: the store's blocks
        grid = _adopt_block(Path(store), grid)
    state = check_store(store, grid)
    path = state.path
    if not _todo(state.done, grid, stop_after):  # no worker needed
        if state.done is None:
            with _claimed(path, grid, True):
                pass
        return open_sweep(path)
    saved = [0]  # blocks in the store, kept up to date by _gather
    with _interrupts_remembered(), _HeldLogs() as held, contextlib.ExitStack() as stack:
        try:
            client = _connect(scheduler, workers, stack)
            with _claimed(path, grid, state.done is None) as done:
                saved[0] = int(done.sum())
                todo = _todo(done, grid, stop_after)
                if todo:
                    client.register_plugin(WarmUp(grid.kind))
                    _gather(client, grid, path, todo, saved, progress)
            held.whole = True  # what distributed says from here on is its closing
            if scheduler is None:  # our own workers: quiet as they close
                client.run(_quiet_logs, on_error="ignore")
        except KeyboardInterrupt:
            held.whole = True  # an interrupt's one line says it all
            stack.pop_all()  # no orderly close of the cluster: it takes seconds and logs
            _stop_workers()
            for partial in path.rglob("*.partial"):  # zarr's temporary of a chunk cut short
                partial.unlink(missing_ok=True)
            raise Interrupted(f"{saved[0]}/{grid.chunks} blocks saved in {path}; run the same "
                              "command to resume") from None
    return open_sweep(path)


def _todo(done: np.ndarray | None, grid: Grid, stop_after: int | None) -> list[int]:
    """The blocks this run computes: those not done, the first ``stop_after`` of them."""
    todo = list(range(grid.chunks)) if done is None else [int(i) for i in np.flatnonzero(~done)]
    return todo if stop_after is None else todo[:stop_after]


STOP = threading.Event()
# NOTE: set by Ctrl-C or SIGTERM during a sweep. The signal also raises KeyboardInterrupt at
# once; the flag stops the sweep at the next block even where library code caught that
# exception on its way (seen once in many runs: a sweep that ran on to its end after Ctrl-C).


@contextlib.contextmanager
def _interrupts_remembered() -> Iterator[None]:
    """SIGINT and SIGTERM set :data:`STOP`, then raise KeyboardInterrupt (the former handlers
    back afterwards); in the main thread only (signals are delivered there)."""
    import signal

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    STOP.clear()

    def remember(signum: int, frame: object) -> None:
        STOP.set()
        raise KeyboardInterrupt

    old = {sig: signal.signal(sig, remember) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)


DISTRIBUTED_LOGGERS = ("distributed", "tornado", "asyncio")
# NOTE: where dask's scheduler, nannies, comms and event loop log: a worker that went away
# mid-task ("Couldn't gather keys", then rescheduled), comms closed while the cluster closes
# (CommClosedError tracebacks), tasks the closing loop drops.


def _handlers_and_loggers() -> list[logging.Handler | logging.Logger]:
    """Every handler of :data:`DISTRIBUTED_LOGGERS` and the loggers below them (distributed
    gives several their own, unpropagated), and each of those loggers without a handler of
    its own at the top (asyncio's records go to Python's last-resort handler)."""
    out: list[logging.Handler | logging.Logger] = []
    for name, logger in sorted(logging.root.manager.loggerDict.items()):
        if isinstance(logger, logging.Logger) and any(
                name == top or name.startswith(top + ".") for top in DISTRIBUTED_LOGGERS):
            out += [h for h in logger.handlers if h not in out]
            if name in DISTRIBUTED_LOGGERS and not logger.handlers:
                out.append(logger)
    return out


class _HeldLogs:
    """Holds back what dask logs in this process during a run; on exit drops it where the
    result is whole (:attr:`whole`, set once every block is written, or on an interrupt,
    whose line says what was saved), else passes it on, so that a run that fails shows why.
    A filter on each handler (:func:`_handlers_and_loggers`): the levels stay as they were,
    and so does what other threads of a library user log elsewhere."""

    def __init__(self) -> None:
        self.whole = False
        self.records: list[tuple[logging.Handler | logging.Logger, logging.LogRecord]] = []
        self.where: list[logging.Handler | logging.Logger] = []

    def __enter__(self) -> _HeldLogs:
        import distributed  # noqa: F401  (its logging configuration: the handlers to hold)

        self.where = _handlers_and_loggers()
        for target in self.where:
            target.addFilter(self._hold(target))
        return self

    def _hold(self, target: logging.Handler | logging.Logger) -> Callable[[logging.LogRecord],
                                                                          bool]:
        def hold(record: logging.LogRecord) -> bool:
            self.records.append((target, record))
            return False
        hold.held_by = self  # type: ignore[attr-defined]
        return hold

    def __exit__(self, *exc: object) -> None:
        for target in self.where:
            for f in list(target.filters):
                if getattr(f, "held_by", None) is self:
                    target.removeFilter(f)
        if self.whole or isinstance(exc[1], InputError):  # a one-line refusal stays one line
            return
        for target, record in self.records:
            target.handle(record)


def _quiet_logs() -> None:
    """On each of our workers once every block is written: nothing but a crash from its
    closing reaches the terminal."""
    for name in DISTRIBUTED_LOGGERS:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    for name, logger in list(logging.root.manager.loggerDict.items()):
        if isinstance(logger, logging.Logger) and name.split(".")[0] in DISTRIBUTED_LOGGERS:
            logger.setLevel(logging.CRITICAL)


def _stop_workers() -> None:
    """Stop this process's worker processes at once (an interrupt): every block written so far
    is whole with its flag; a block being written has no flag and is computed again."""
    import multiprocessing

    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    for child in multiprocessing.active_children():
        child.kill()


def _write_metadata(path: Path, grid: Grid) -> None:
    """Metadata, coordinates and fill values of a new store at ``path`` (no block)."""
    import warnings

    with warnings.catch_warnings():  # zarr's note that v3 does not yet specify consolidation
        warnings.filterwarnings("ignore", "Consolidated metadata", UserWarning)
        _dataset(grid, None, None).to_zarr(str(path), mode="w", compute=False,
                                           consolidated=True, encoding=_encoding(grid))


class StoreWriteError(InputError):
    """Writing the store failed (a full disk, permissions, a read-only mount): one line naming
    the store and the error, with what was saved and how to resume."""


def _write_failed(path: Path, e: OSError, saved: int, total: int) -> StoreWriteError:
    """The one line of an OSError ``e`` met writing the store at ``path``."""
    for partial in path.rglob("*.partial"):  # zarr's temporary of a chunk cut short
        with contextlib.suppress(OSError):
            partial.unlink()
    return StoreWriteError(f"store {path}: cannot write ({e.strerror or _first_line(e)}); "
                           f"{saved}/{total} blocks saved; run the same command to resume "
                           "once the store can be written")


def _busy(path: Path) -> InputError:
    return InputError(f"store {path}: another sweep is writing it now; run the command again "
                      "when it has finished (it resumes)")


def _lock(fd: int, path: Path) -> None:
    """An exclusive ``flock`` on the open folder ``fd``, or :func:`_busy` at once (the lock
    goes with the process: a killed run leaves none behind)."""
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise _busy(path) from None


def _created(path: Path, grid: Grid) -> int | None:
    """Make the store at ``path`` whole under a temporary name beside it, locked, and rename
    it into place (atomic: another run sees no store or a whole one); the open, locked folder,
    or ``None`` where another run's store took the place first. An OSError leaves nothing."""
    import secrets

    folder = path.parent if str(path.parent) else Path(".")
    tmp = folder / f".{path.name}.{os.getpid()}-{secrets.token_hex(4)}.new"
    os.mkdir(tmp)  # the umask's mode, as any folder the user makes
    fd = None
    try:
        _write_metadata(tmp, grid)  # (zarr's mode "w" makes the folder anew: lock after)
        fd = os.open(tmp, os.O_RDONLY)
        _lock(fd, tmp)  # ours alone: no one else knows the name; the lock follows the rename
        os.rename(tmp, path)  # replaces an empty folder; never a non-empty one
    except OSError as e:
        if fd is not None:
            os.close(fd)
        shutil.rmtree(tmp, ignore_errors=True)
        if e.errno in (errno.ENOTEMPTY, errno.EEXIST) and path.is_dir():
            return None
        raise
    return fd


@contextlib.contextmanager
def _claimed(path: Path, grid: Grid, new: bool) -> Iterator[np.ndarray]:
    """The store at ``path`` locked for this run (:func:`_busy` if another run holds it),
    made first when ``new``; yields its ``done`` flags as they stand once locked."""
    import zarr

    fd = None
    try:
        if new:
            try:
                fd = _created(path, grid)
            except OSError as e:
                raise _write_failed(path, e, 0, grid.chunks) from None
        if fd is None:  # an existing store, or one another run made a moment ago
            problem = _mismatch(path, _stored_identity(path), grid)
            if problem:
                raise InputError(f"{problem}; give a new store path or delete it")
            fd = os.open(path, os.O_RDONLY)
            _lock(fd, path)
        yield np.asarray(zarr.open_array(str(path / "done"), mode="r")[:], dtype=bool)
    finally:
        if fd is not None:
            os.close(fd)  # releases the lock


def _gather(client: object, grid: Grid, path: Path, todo: list[int], saved: list[int],
            progress: Callable[[SweepProgress], None] | None) -> None:
    """Keep every worker busy with one block running and one queued; write each block (then
    its flag) as it arrives, counting the flags in ``saved[0]``; cancel what is left if stopped
    early or on an error."""
    finished = saved[0]
    from distributed import as_completed

    start = time.perf_counter()
    window = 2 * max(1, sum(client.nthreads().values()))
    queue = iter(todo)
    index: dict = {}
    try:
        arrays = _open_arrays(path, grid)
    except OSError as e:
        raise _write_failed(path, e, finished, grid.chunks) from None

    def submit(chunk: int) -> object:
        future = client.submit(compute_block, grid.kind, grid.block_values(chunk),
                               pure=False)
        index[future] = chunk
        return future

    running = as_completed([submit(c) for c in itertools.islice(queue, window)],
                           loop=client.loop)
    try:
        for future in running:
            if STOP.is_set():
                raise KeyboardInterrupt
            chunk = index.pop(future)
            data = future.result()
            try:
                _write_block(arrays, grid, chunk, data)
                _mark_done(arrays, chunk)
            except OSError as e:  # ENOSPC, EACCES, EROFS, EDQUOT…: the store stops here
                raise _write_failed(path, e, finished, grid.chunks) from None
            finished += 1
            saved[0] = finished
            if progress is not None:
                progress(SweepProgress(chunk, finished, grid.chunks, time.perf_counter() - start))
            following = next(queue, None)
            if following is not None:
                running.add(submit(following))
    finally:
        if index:
            client.cancel(list(index))


def serial_sweep(kind: str | Kind, axes: Mapping[str, Sequence[float]], chunk: int | None = None,
                 progress: Callable[[SweepProgress], None] | None = None) -> xr.Dataset:
    """The same map in this process, block by block, no dask and no store: the reference of
    :func:`run_sweep` (value for value) and its one-core baseline."""
    grid = make_grid(kind, axes, chunk)
    sizes = grid.kind.extra_sizes
    data = {f.name: np.full(grid.shape + tuple(sizes[d] for d in f.dims), f.fill, f.dtype)
            for f in grid.kind.fields}
    start = time.perf_counter()
    for c in range(grid.chunks):
        block = compute_block(grid.kind, grid.block_values(c))
        for name, values in block.items():
            data[name][grid.region(c)] = values
        if progress is not None:
            progress(SweepProgress(c, c + 1, grid.chunks, time.perf_counter() - start))
    return _dataset(grid, data, np.ones(grid.chunks, dtype=bool))
