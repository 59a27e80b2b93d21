"""The core install in a subprocess: the extras of the ``test`` install hidden from imports.

The test suite runs with the ``test`` extra, which brings mpmath, SciPy, hypothesis and Dask;
a user who ran ``pip install boundest`` has none of them. :data:`HIDE_EXTRAS` is Python source
that, run first in a subprocess, makes importing any of them fail.
"""

#: what the extras bring; the library may import them only inside the functions that need them
EXTRAS_ONLY = ("mpmath", "scipy", "hypothesis", "dask", "distributed", "pytest", "filterpy",
               "mkdocs", "codac")

HIDE_EXTRAS = f"""
import importlib.abc, sys
class Hide(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {EXTRAS_ONLY!r}:
            raise ImportError(f"{{name}} is not in the core install (hidden by the test)")
        return None
sys.meta_path.insert(0, Hide())
"""
