"""System objects: plants (with measured outputs), uncertainty, pole regions, plant sets, controllers.

The objects every design, analysis and simulation takes: :class:`Plant`,
the norm-bounded uncertainty :class:`NormBounded`, the pole regions
(:class:`Disk`, :class:`HalfPlane`, :class:`ConicSector`), sampled plant
sets (:func:`sample_plants`), the common design result :class:`Controller`
and the input-memory law :class:`InputMemoryFeedback`, with the eigenvalue
and PBH tests that they need (:mod:`robustctl.systems.stability`). This
layer imports only robustctl's base modules (errors, validation).
"""

from .controller import Controller, ControllerBatch
from .input_memory import InputMemoryFeedback
from .noise import noise_covariance
from .plant import Plant
from .regions import ConicSector, Disk, HalfPlane
from .scenarios import PlantSamples, sample_plants
from .stability import STABILITY_MARGIN, is_schur_stable, spectral_radius
from .uncertainty import NormBounded

__all__ = ["Plant", "NormBounded", "Controller", "ControllerBatch", "InputMemoryFeedback", "Disk", "HalfPlane",
           "ConicSector", "sample_plants", "PlantSamples", "noise_covariance", "spectral_radius", "is_schur_stable",
           "STABILITY_MARGIN"]
