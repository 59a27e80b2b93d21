"""Reading a UTF-8 text file with one clear error naming the file and line.

Shared by every reader of user files (model text, CSV data): it sits below all layers.
"""

from __future__ import annotations

import gzip
import zlib
from pathlib import Path

__all__ = ["read_text"]


def read_text(path: str | Path, error: type[ValueError] = ValueError) -> str:
    """The text of a UTF-8 file (an initial byte-order mark is dropped); a ``.gz`` file is
    decompressed first.

    Raises
    ------
    error
        If the file cannot be read, is UTF-16, is not valid UTF-8 or holds a NUL character (a
        binary file); the one-line message names the file and the line.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None
    if path.suffix == ".gz":
        try:
            data = gzip.decompress(data)
        except (OSError, EOFError, zlib.error) as exc:
            raise error(f"{path}: not a gzip file, or a truncated one: {exc}") from None
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise error(f"{path}:1: UTF-16 text (byte-order mark {data[:2].hex(' ')}); "
                    "save it as UTF-8")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise error(f"{path}:{line}: not UTF-8 text (byte 0x{data[exc.start]:02x} at "
                    f"offset {exc.start}; a binary file?)") from None
    nul = text.find("\0")
    if nul >= 0:
        line = text.count("\n", 0, nul) + 1
        raise error(f"{path}:{line}: NUL character at offset {nul} (a binary or UTF-16 "
                    "file?)")
    return text
