"""Set domains: SIVIA, subpavings and images of subpavings (Jaulin et al. 2001)."""

from .image import image
from .sivia import separators, sivia
from .subpaving import Subpaving, box_difference

__all__ = ["Subpaving", "box_difference", "image", "separators", "sivia"]
