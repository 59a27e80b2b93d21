"""Test session set-up.

Kernels compile on first use (Numba), so a test's first example can take seconds: hypothesis
deadlines are off. The stale Numba cache guard runs when boundest is imported.

mpmath's working precision is global state: test modules that set it at import would set it for
every test collected after them. Every test therefore starts at 256 bits and leaves the
precision as it found it (a test that needs more or less sets it itself).
"""

import mpmath
import pytest
from hypothesis import HealthCheck, settings

#: the autouse precision fixture below is function scoped; it holds nothing an example changes
settings.register_profile("boundest", deadline=None,
                          suppress_health_check=[HealthCheck.function_scoped_fixture])
settings.load_profile("boundest")


@pytest.fixture(autouse=True)
def _mpmath_precision():
    with mpmath.workprec(256):
        yield
