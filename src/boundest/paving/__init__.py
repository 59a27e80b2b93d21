"""Set domains: SIVIA, subpavings and images of subpavings (Jaulin et al. 2001)."""

from .image import image
from .roots import Roots, solve_square
from .sivia import separators, sivia
from .subpaving import Subpaving, box_difference

__all__ = ["Roots", "Subpaving", "box_difference", "image", "separators", "sivia", "solve_square"]
