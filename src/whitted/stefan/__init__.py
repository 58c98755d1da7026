"""The Stefan problem: how a hollow piece of ice with water inside melts.

Physics only (fields and surfaces); it never imports the renderer. ``docs/stefan.md`` has the
equations, the properties and their sources, the method and the validation.
"""

from .properties import ICE, LATENT_HEAT, WATER, Phase, Properties
from .solver import Air, EnthalpySolver, Faces, stability_limit

__all__ = ["ICE", "LATENT_HEAT", "WATER", "Air", "EnthalpySolver", "Faces", "Phase",
           "Properties", "stability_limit"]
