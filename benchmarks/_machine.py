"""What the benchmarks record about the machine they ran on."""

from __future__ import annotations


def cpu_model() -> str | None:
    """The CPU model name from /proc/cpuinfo (None where there is no such file)."""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def emit(doc: dict, out: str | None) -> None:
    """Print the benchmark's JSON document on stdout and write it to ``out`` (if given), as
    strict JSON with the commands' conventions (``boundest.commands.jsonable``: infinities as
    ``"inf"``/``"-inf"``, NaN as ``null``)."""
    import json
    from pathlib import Path

    from boundest.commands import jsonable

    text = json.dumps(jsonable(doc), indent=1, allow_nan=False, default=float)
    print(text)
    if out:
        Path(out).write_text(text + "\n")
