"""Test session set-up.

Kernels compile on first use (Numba), so a test's first example can take seconds: hypothesis
deadlines are off. The stale Numba cache guard runs when boundest is imported.
"""

from hypothesis import settings

settings.register_profile("boundest", deadline=None)
settings.load_profile("boundest")
