"""The checks every command makes of its command line before any work.

A bad value, options that cannot go together, an output path that cannot be written, a missing
optional extra or a run larger than the machine: each is one line on standard error and exit
code 2, before anything is computed or written (``docs/getting-started.md``, "Bad input").

- The numeric options are parsed by the types below (``type=`` of ``argparse``): a value
  outside its meaning (``--dt 0``, ``--q -1``, ``--rel-eps 1``) is refused by the parser, which
  names the option and the value in one line (:class:`Parser`).
- :func:`check_outputs` and :func:`check_input` check ``--out``, ``--json`` and ``--data``;
  :func:`require_extra` checks that an optional extra a command needs is installed.
- :func:`check_size` compares a run's estimated memory with the memory the machine has: more is
  refused, naming the estimate and the option that sets it; a large but feasible run is
  announced in one line on standard error before it starts.

Like the rest of ``boundest.commands`` at import, this module imports neither NumPy nor
Numba, so that an argument error returns at once.
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import sys
from collections.abc import Callable
from pathlib import Path

__all__ = ["LARGE_BYTES", "Parser", "announce", "available_memory", "check_input",
           "check_outputs", "check_size", "count", "fraction", "gib", "positive_float",
           "require_extra", "whole"]

#: A run whose estimated memory exceeds this is announced before it starts (1 GiB: five times
#: the largest default run, the range-only robot's 0.3 GiB peak with its figure process).
LARGE_BYTES = 1 << 30


class Parser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line: ``prog: error: message``, and where
    to read the usage (the usage block of argparse is several lines)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (usage: {self.prog} --help)\n")


# -- types of the numeric options ----------------------------------------------------------
def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None


def positive_float(text: str) -> float:
    """A finite number > 0 (a step, a precision, a width)."""
    v = _number(text)
    if not (math.isfinite(v) and v > 0.0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return v


def fraction(text: str) -> float:
    """A number in [0, 1[ (a relative decrease below which a propagation stops)."""
    v = _number(text)
    if not 0.0 <= v < 1.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 1[, got {text!r}")
    return v


def whole(minimum: int) -> Callable[[str], int]:
    """The ``type=`` of a whole number at least ``minimum`` (a count)."""

    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"must be a whole number >= {minimum}, got {text!r}") from None
        if v < minimum:
            raise argparse.ArgumentTypeError(f"must be a whole number >= {minimum}, got {text!r}")
        return v

    parse.__name__ = f"whole number >= {minimum}"
    return parse


# -- paths ---------------------------------------------------------------------------------
def _writable(folder: Path) -> bool:
    return os.access(folder, os.W_OK | os.X_OK)


def check_outputs(out: str | None = None, json: str | None = None,
                  extra: tuple[tuple[str, str], ...] = ()) -> None:
    """Refuse, before any work, an ``--out`` folder or ``--json`` file that cannot be written.

    ``--out FOLDER`` is created, with its missing parents, when the figures are written: an
    existing ``FOLDER`` must be a writable folder, else its nearest existing parent must be.
    ``--json FILE`` must not be a folder, and its folder must exist and be writable (no folder
    is created for it).
    ``extra``: more files the command writes, as (option, path), checked like ``--json``.

    Raises
    ------
    ValueError
        One line naming the option and the path.
    """
    if out is not None:
        p = Path(out)
        if p.exists():
            if not p.is_dir():
                raise ValueError(f"--out {out}: is a file, not a folder (--out names the folder "
                                 "the figures go to)")
            if not _writable(p):
                raise ValueError(f"--out {out}: the folder is not writable")
        else:
            base = p.parent
            while not base.exists() and base != base.parent:  # the folders --out creates
                base = base.parent
            if not base.is_dir():
                raise ValueError(f"--out {out}: cannot create it, {base} is a file")
            if not _writable(base):
                raise ValueError(f"--out {out}: cannot create it, {base} is not writable")
    for option, path in ((("--json", json),) if json is not None else ()) + tuple(extra):
        p = Path(path)
        if p.is_dir():
            raise ValueError(f"{option} {path}: is a folder; name a file")
        parent = p.parent
        if not parent.is_dir():
            what = ("is a file, not a folder" if parent.exists() else
                    "does not exist (it is not created)")
            raise ValueError(f"{option} {path}: {parent} {what}")
        if p.exists() and not os.access(p, os.W_OK):
            raise ValueError(f"{option} {path}: the file is not writable")
        if not p.exists() and not _writable(parent):
            raise ValueError(f"{option} {path}: the folder {parent} is not writable")


def check_input(option: str, path: str | None, kind: str = "file") -> None:
    """Refuse an input path (``--data``, ``--beacons``, a model file) that does not exist, is
    not a ``kind`` (``"file"`` or ``"folder"``) or cannot be read: one line naming
    ``option`` and the path."""
    if path is None:
        return
    p = Path(path)
    if not p.exists():
        raise ValueError(f"{option} {path}: no such {kind}")
    if kind == "folder" and not p.is_dir():
        raise ValueError(f"{option} {path}: is a file; {option} names a folder")
    if kind == "file" and p.is_dir():
        raise ValueError(f"{option} {path}: is a folder; {option} names a file")
    if not os.access(p, os.R_OK | (os.X_OK if kind == "folder" else 0)):
        raise ValueError(f"{option} {path}: cannot be read (permission denied)")


# -- optional extras -----------------------------------------------------------------------
def require_extra(option: str, module: str, extra: str, what: str) -> None:
    """Refuse ``option`` in one line when ``module``, from the optional ``extra``, is missing:
    ``"{option} needs {what}: pip install 'boundest[{extra}]'"``."""
    try:
        importlib.import_module(module)
    except ImportError:
        raise ValueError(f"{option} needs {what}: pip install 'boundest[{extra}]'") from None


# -- sizes ---------------------------------------------------------------------------------
def available_memory() -> int | None:
    """Bytes of memory available to a new allocation: ``MemAvailable`` of ``/proc/meminfo``
    (Linux), else the free physical pages, else all physical pages; None when unknown."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    for pages in ("SC_AVPHYS_PAGES", "SC_PHYS_PAGES"):
        try:
            n, size = os.sysconf(pages), os.sysconf("SC_PAGE_SIZE")
        except (AttributeError, ValueError, OSError):
            continue
        if n > 0 and size > 0:
            return n * size
    return None


def gib(n: float) -> str:
    """Bytes as a short text (``3.2 GiB``, ``480 MiB``, ``1.2e+05 GiB``)."""
    if n >= 1 << 30:
        g = n / (1 << 30)
        return f"{g:.3g} GiB" if g < 1e3 else f"{g:,.0f} GiB" if g < 1e7 else f"{g:.2g} GiB"
    return f"{n / (1 << 20):.0f} MiB"


def count(n: float) -> str:
    """A count as a short text: ``6,400``, ``6.4e+10`` beyond 10^12, ``more than 1e308``."""
    if not math.isfinite(n):
        return "more than 1e308"
    return f"{n:,.0f}" if n < 1e12 else f"{n:.3g}"


def announce(line: str) -> None:
    """One line on standard error, before a long run starts."""
    print(f"boundest: {line}", file=sys.stderr, flush=True)


def check_size(need: float, what: str, option: str, large: bool = False,
               available: int | None = None) -> bool:
    """Refuse a run whose estimated memory ``need`` (bytes) exceeds the memory available;
    announce one that needs more than :data:`LARGE_BYTES`, or that the caller calls ``large``.

    ``what`` says what the estimate counts (``"6,400,000 slices of 6 KiB"``); ``option``, the
    option that sets it, with its value (``"--dt 1e-05"``). Returns whether the run was
    announced.

    Raises
    ------
    ValueError
        ``option: what need about X of memory, more than the Y available here``.
    """
    avail = available_memory() if available is None else available
    if not math.isfinite(need):
        raise ValueError(f"{option}: {what}: more memory than any machine has")
    if avail is not None and need > avail:
        raise ValueError(f"{option}: {what}: about {gib(need)} of memory, more than the "
                         f"{gib(avail)} available here")
    if large or need > LARGE_BYTES:
        of = f" of the {gib(avail)} available" if avail is not None else ""
        announce(f"a large run: {option}: {what}: about {gib(need)} of memory{of} ...")
        return True
    return False
