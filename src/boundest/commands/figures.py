"""A command's figures drawn in child processes, so that importing matplotlib overlaps the solve.

``matplotlib`` takes about 0.3 s to import and its first figure a few tens of milliseconds more
to load its fonts: a fifth of a warm ``boundest run``. A command starts a :class:`FigureWorker`
before its numerical work. On Linux the worker forks a child that imports matplotlib (and the
modules the command names) on another core while the parent computes; once warm, that child
forks a second one, which shares its imports, so that two figures are drawn at a time. The
command hands the worker module-level functions to call with its results
(:meth:`FigureWorker.submit`, which pickles them; the heaviest first), goes on (JSON, tables)
and collects what the children printed, in the order submitted (:meth:`FigureWorker.finish`);
an error in a child is raised in the parent with its traceback. A child whose parent is gone
exits. Elsewhere (no safe ``fork``: Windows and macOS), on one CPU, in a process that runs
other threads (a fork copies none of them, and whatever lock one holds stays held in the
child: a notebook kernel, a Dask client), with ``BOUNDEST_FIGURE_PROCESS=0``, or when no process
can be started, the same functions run in the command's own process, one after the other.
"""

from __future__ import annotations

import contextlib
import importlib
import io
import os
import pickle
import sys
import threading
import traceback
from collections.abc import Callable, Iterable
from typing import Any

__all__ = ["FigureError", "FigureWorker"]

#: seconds between two checks, by an idle child, that its parent is still there
_POLL_S = 0.25


class FigureError(RuntimeError):
    """A figure function failed in a child process (the message holds its traceback)."""


def _warm(preload: tuple[str, ...]) -> None:
    """Import matplotlib (Agg) and ``preload``; draw one text (loads the fonts)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from . import pyplot

    pyplot()
    for name in preload:
        importlib.import_module(name)
    fig = Figure(figsize=(1, 1))
    FigureCanvasAgg(fig)
    fig.text(0.5, 0.5, "0.5 m")
    fig.canvas.draw()


def _serve(conns: list[Any], preload: tuple[str, ...]) -> None:
    """The first child: warm up, fork the second child (one connection each), serve jobs."""
    parent = os.getppid()
    _warm(preload)
    if len(conns) > 1:
        pid = os.fork()
        if pid == 0:  # the second child: its own connection, the first child as its parent
            try:
                _loop(conns[1], os.getppid())
            finally:
                os._exit(0)
    _loop(conns[0], parent)


def _loop(conn: Any, parent: int) -> None:
    """Run ``(func, args)`` jobs from ``conn`` until ``None``, or until the parent is gone."""
    while True:
        while not conn.poll(_POLL_S):
            if os.getppid() != parent:
                return
        try:
            job = conn.recv()
        except EOFError:
            return
        if job is None:
            return
        out, err = io.StringIO(), io.StringIO()
        try:
            func, args = job
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                func(*args)
            conn.send(("ok", out.getvalue(), err.getvalue(), None))
        except BaseException as exc:
            tb = traceback.format_exc()
            try:  # the exception itself, so that the parent can raise it as it is
                pickle.dumps(exc)
            except Exception:  # one that does not pickle: the traceback alone
                exc = None
            conn.send(("error", out.getvalue(), err.getvalue() + tb, exc))


class FigureWorker:
    """Draws a command's figures in forked children, or in-process where that is not possible.

    Parameters
    ----------
    preload : iterable of str
        Modules the figure functions need (their plotting and data modules): the children
        import them while the parent computes, so that unpickling the results imports nothing.
    processes : int
        Children drawing at a time (default 2; 0: in-process). With one CPU the figures are
        drawn in-process: a child would only take turns with the solve.
    """

    def __init__(self, preload: Iterable[str] = (), processes: int = 2) -> None:
        self._conns: list[Any] = []
        self._proc: Any = None
        self._jobs: list[tuple[Callable[..., Any], tuple]] = []
        self._idle: list[int] = []
        self._busy: dict[int, int] = {}  # connection -> job index
        self._results: dict[int, tuple[str, str, str, BaseException | None]] = {}
        cpus = os.cpu_count() or 1
        processes = 0 if cpus < 2 else min(processes, cpus)
        if not (processes > 0 and sys.platform.startswith("linux")
                and threading.active_count() == 1
                and os.environ.get("BOUNDEST_FIGURE_PROCESS", "1") != "0"):
            return
        import multiprocessing

        ctx = multiprocessing.get_context("fork")
        pipes = [ctx.Pipe() for _ in range(processes)]
        proc = ctx.Process(target=_serve, args=([c for _, c in pipes], tuple(preload)),
                           daemon=True, name="boundest-figures")
        try:
            proc.start()
        except OSError:  # no process to spare: draw in-process
            for a, b in pipes:
                a.close()
                b.close()
            return
        for _, c in pipes:
            c.close()
        self._conns = [p for p, _ in pipes]
        self._idle = list(range(processes))
        self._proc = proc

    @property
    def forked(self) -> bool:
        """Whether the figures are drawn in child processes."""
        return self._proc is not None

    def submit(self, func: Callable[..., Any], *args: Any) -> None:
        """Call ``func(*args)`` for its figures; in a child, both must pickle (``func`` a
        module-level function). In-process it runs at once."""
        if self._proc is None:
            func(*args)
            return
        self._jobs.append((func, args))
        self._dispatch()

    def _dispatch(self) -> None:
        while self._idle and len(self._busy) + len(self._results) < len(self._jobs):
            i = self._idle.pop(0)
            job = len(self._busy) + len(self._results)
            self._conns[i].send(self._jobs[job])
            self._busy[i] = job

    def finish(self) -> None:
        """Wait for every submitted function, print what each printed (in the order
        submitted), stop the children. If one failed: its ``OSError`` or ``ValueError`` is
        raised as it is (as the command would raise it in-process), any other failure as
        :class:`FigureError` with the child's traceback."""
        if self._proc is None:
            return
        from multiprocessing.connection import wait

        try:
            while self._busy:
                ready = wait([self._conns[i] for i in self._busy])
                for i in [i for i in self._busy if self._conns[i] in ready]:
                    job = self._busy.pop(i)
                    try:
                        self._results[job] = self._conns[i].recv()
                    except EOFError:  # that child is gone: no more jobs for it
                        self._results[job] = ("error", "", "the figure process died\n", None)
                        continue
                    self._idle.append(i)
                self._dispatch()
        finally:
            self.close()
        failure = None
        for job in range(len(self._jobs)):
            status, out, err, exc = self._results.get(
                job, ("error", "", "not run: the figure processes died\n", None))
            sys.stdout.write(out)
            if status == "ok":
                sys.stderr.write(err)
            elif failure is None:
                failure = err, exc
        sys.stdout.flush()
        if failure is not None:
            err, exc = failure
            if isinstance(exc, (OSError, ValueError)):  # bad input (an --out that is a file):
                raise exc  # the one-line error the command gives in-process
            raise FigureError(f"drawing a figure failed in a figure process:\n{err}")

    def close(self) -> None:
        """Stop the children (a job still running is dropped); :meth:`finish` calls it, and so
        does leaving a ``with`` block, so that a command that fails leaves no child behind."""
        if self._proc is None:
            return
        for conn in self._conns:
            with contextlib.suppress(OSError):
                conn.send(None)
            conn.close()
        self._proc.join(timeout=1)
        if self._proc.is_alive():  # still drawing: the second child follows it out
            self._proc.terminate()
            self._proc.join(timeout=1)
        self._proc = None

    def __enter__(self) -> FigureWorker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
