"""A griffe extension for the API pages: Sphinx roles in docstrings (``:meth:`Tube.x```,
``:func:`f```, ...) are written as plain code, which mkdocstrings' NumPy style does not
resolve."""

from __future__ import annotations

import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:meth|func|class|mod|attr|data|obj|exc):`~?([^`]+)`")


class SphinxRolesAsCode(griffe.Extension):
    """Rewrite ``:role:`target``` as ```target``` in every docstring."""

    def on_object(self, *, obj: griffe.Object, **kwargs: Any) -> None:  # noqa: ARG002
        if obj.docstring is not None:
            obj.docstring.value = _ROLE.sub(r"``\1``", obj.docstring.value)
