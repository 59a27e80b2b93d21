"""Run independent pieces of work on a ``concurrent.futures.Executor``, in a deterministic order.

Every function of boundest that takes ``executor=`` takes any ``concurrent.futures.Executor``:
``None`` runs in this process, a ``ProcessPoolExecutor`` on the local cores, and a Dask
cluster through ``distributed.Client(address).get_executor()`` (``pip install
boundest[distributed]``; docs/distributed.md). The scheduling, retries after a lost worker and
data transfers are the executor's; this module only cuts the work into chunks, submits them,
shows progress as they finish and puts the results back in the order of the inputs, so that the
result never depends on the number of workers or on which finished first.

A task that raises does not surface as a worker's bare traceback: :class:`TaskError` names the
index and the ``repr`` of the failing input, the error, and keeps the worker's traceback in
``worker_traceback``.

This module imports nothing from boundest's numerical layers (it sits below ``interval``).

Examples
--------
>>> map_chunked(abs, [-3, 1, -2], chunk=2)
[3, 1, 2]
>>> table = run_batch(lambda v: {"square": v * v, "neg": -v}, [1.0, 2.0, 3.0], progress=False)
>>> table["square"].tolist(), len(table)
([1.0, 4.0, 9.0], 3)
"""

from __future__ import annotations

import dataclasses
import time
import traceback
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import Executor, Future, as_completed
from typing import Any

import numpy as np

from ._progress import Progress

__all__ = ["BatchTable", "TaskError", "client_executor", "executor_workers", "map_chunked",
           "run_batch"]

_REPR = 300  # characters of an input's repr in an error message


class TaskError(RuntimeError):
    """A task failed: the failing input's index and ``repr``, the error, the worker's
    traceback."""

    def __init__(self, index: int, input_repr: str, error: str, worker_traceback: str = ""):
        self.index = index
        self.input_repr = input_repr
        self.error = error
        self.worker_traceback = worker_traceback
        super().__init__(f"input {index} ({input_repr}) failed: {error}")


@dataclasses.dataclass
class _Failure:
    """What a task sends back instead of raising (so that the driver can name the input)."""

    index: int
    input_repr: str
    error: str
    worker_traceback: str


def _short_repr(value: Any) -> str:
    try:
        r = repr(value)
    except Exception as exc:  # a repr that raises must not hide the real error
        r = f"<{type(value).__name__}: repr failed: {exc}>"
    return r if len(r) <= _REPR else r[:_REPR - 3] + "..."


def _chunk_task(fn: Callable[[Any], Any], start: int, items: Sequence[Any]
                ) -> tuple[list[Any], float, float] | _Failure:
    """``[fn(item) for item in items]``, the seconds it took and the CPU seconds of its thread,
    on a worker; a failure names the input (its index in the whole run is ``start + j``)."""
    t0, c0 = time.perf_counter(), time.thread_time()
    out = []
    for j, item in enumerate(items):
        try:
            out.append(fn(item))
        except Exception as exc:
            return _Failure(start + j, _short_repr(item), f"{type(exc).__name__}: {exc}",
                            traceback.format_exc())
    return out, time.perf_counter() - t0, time.thread_time() - c0


def executor_workers(executor: Executor | None) -> int:
    """How many tasks ``executor`` runs at once (1 for None; a Dask executor's total threads)."""
    if executor is None:
        return 1
    n = getattr(executor, "_max_workers", None)
    if isinstance(n, int) and n > 0:
        return n
    client = getattr(executor, "_client", None)  # distributed.ClientExecutor
    if client is not None:
        try:
            return max(1, sum(client.nthreads().values()))
        except Exception:
            return 1
    return 1


def client_executor(address: str) -> Executor:
    """The ``concurrent.futures.Executor`` of a Dask cluster whose scheduler is at
    ``address``; a clear error when Dask distributed is not installed."""
    try:
        from distributed import Client
    except ImportError as exc:
        raise RuntimeError("a Dask scheduler needs Dask distributed: "
                           "pip install 'boundest[distributed]'") from exc
    return Client(address).get_executor()


def map_chunked(fn: Callable[[Any], Any], items: Iterable[Any],
                executor: Executor | None = None, *, chunk: int | None = None,
                progress: bool | None = False, desc: str | None = None,
                stats: dict | None = None) -> list[Any]:
    """``[fn(item) for item in items]``, run as tasks of ``chunk`` consecutive items.

    Parameters
    ----------
    fn : callable
        Applied to each item (on a worker: it and the items must pickle; with a
        ``ProcessPoolExecutor`` that excludes lambdas, Dask pickles them by value).
    items : iterable
        The inputs.
    executor : concurrent.futures.Executor, optional
        Where the tasks run; None: in this process, one item after the other.
    chunk : int, optional
        Items per task (default: about four tasks per worker of the executor; the results do
        not depend on it).
    progress : bool or None
        A progress bar over the items, advanced as tasks finish (False: none; drawn on a
        terminal only).
    desc : str, optional
        The bar's label.
    stats : dict, optional
        Filled with ``tasks``, ``chunk``, ``compute_s`` and ``cpu_s`` (seconds and CPU seconds
        each task spent in ``fn``, in task order) and ``wall_s``.

    Returns
    -------
    list
        The results in the order of ``items``, whatever the order the tasks finished in.

    Raises
    ------
    TaskError
        When a call raises (or a task cannot be run): the failing input's index and repr and the
        error; the tasks not started yet are cancelled.
    """
    items = list(items)
    n = len(items)
    if chunk is None:
        chunk = max(1, -(-n // (4 * executor_workers(executor))))
    if chunk < 1:
        raise ValueError(f"chunk must be at least 1, got {chunk}")
    starts = list(range(0, n, chunk))
    parts: list[Any] = [None] * len(starts)
    t0 = time.perf_counter()
    with Progress(progress, desc=desc, total=n, delay=0.0) as bar:
        if executor is None:
            for i, s in enumerate(starts):
                parts[i] = _chunk_task(fn, s, items[s:s + chunk])
                if isinstance(parts[i], _Failure):
                    _raise(parts[i])
                bar.update(len(parts[i][0]))
        else:
            futures: dict[Future, int] = {}
            try:
                for i, s in enumerate(starts):
                    futures[executor.submit(_chunk_task, fn, s, items[s:s + chunk])] = i
                for fut in as_completed(futures):
                    i = futures[fut]
                    try:
                        parts[i] = fut.result()
                    except Exception as exc:  # the task never ran: pickling, a broken pool
                        s = starts[i]
                        raise TaskError(s, _short_repr(items[s]), f"the task of inputs {s}.."
                                        f"{min(s + chunk, n) - 1} could not run: "
                                        f"{type(exc).__name__}: {exc}") from exc
                    if isinstance(parts[i], _Failure):
                        _raise(parts[i])
                    bar.update(len(parts[i][0]))
            finally:
                for fut in futures:
                    fut.cancel()
    if stats is not None:
        stats.update(tasks=len(starts), chunk=chunk, compute_s=[p[1] for p in parts],
                     cpu_s=[p[2] for p in parts],
                     wall_s=time.perf_counter() - t0)
    return [r for p in parts for r in p[0]]


def _raise(f: _Failure) -> None:
    err = TaskError(f.index, f.input_repr, f.error, f.worker_traceback)
    err.add_note("worker traceback:\n" + f.worker_traceback.rstrip())
    raise err


class BatchTable(Mapping):
    """The results of :func:`run_batch` as columns: ``table[name]`` is a NumPy array whose first
    axis is the input (an object array where the rows' shapes differ)."""

    def __init__(self, columns: dict[str, np.ndarray], time_s: float):
        self.columns = columns
        self.time_s = time_s

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __iter__(self):
        return iter(self.columns)

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def to_json(self) -> dict[str, list]:
        """Column name -> nested lists (floats may be NaN or infinite: write them with
        ``boundest.commands.dumps`` for strict JSON)."""
        return {k: v.tolist() for k, v in self.columns.items()}

    def __repr__(self) -> str:
        cols = ", ".join(f"{k}{tuple(v.shape)}" for k, v in self.columns.items())
        return f"BatchTable(rows={len(self)}, columns=[{cols}], time_s={self.time_s:.3g})"


def _row(result: Any) -> dict[str, Any]:
    if isinstance(result, Mapping):
        return dict(result)
    if dataclasses.is_dataclass(result) and not isinstance(result, type):
        return {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
    return {"value": result}


def _column(values: list[Any]) -> np.ndarray:
    arrays = [np.asarray(v) for v in values]
    if all(a.shape == arrays[0].shape and a.dtype != object for a in arrays):
        return np.stack(arrays)
    col = np.empty(len(values), dtype=object)
    col[:] = values
    return col


def run_batch(fn: Callable[[Any], Any], inputs: Iterable[Any],
              executor: Executor | None = None, *, chunk: int | None = None,
              progress: bool | None = None, stats: dict | None = None) -> BatchTable:
    """Run one estimator over many inputs and return the results as one table.

    ``fn(input)`` returns a mapping of named values, a dataclass (its fields) or one value
    (column ``value``): any scenario's solve wrapped to return what to keep, or a user's
    callable. Row ``i`` of every column is input ``i``, with any executor and any number of
    workers (``map_chunked`` runs the tasks; a failing input raises :class:`TaskError`).
    """
    t0 = time.perf_counter()
    rows = [_row(r) for r in map_chunked(fn, inputs, executor, chunk=chunk, progress=progress,
                                         desc="batch", stats=stats)]
    names: list[str] = []
    for r in rows:
        names += [k for k in r if k not in names]
    missing = [(i, k) for i, r in enumerate(rows) for k in names if k not in r]
    if missing:
        i, k = missing[0]
        raise ValueError(f"the result of input {i} has no field {k!r} (every result must have "
                         f"the same fields: {names})")
    cols = {k: _column([r[k] for r in rows]) for k in names}
    return BatchTable(cols, time.perf_counter() - t0)
