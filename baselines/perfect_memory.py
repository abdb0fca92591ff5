"""``perfect-memory``: Perfect Memory route following, Baddeley et al. (2012).

The memory is every training view of the route (the env's ``route_views``); the
familiarity of a scanned view is its smallest RMS image difference to any of them
("exhaustive comparison with the set of views experienced during training", Baddeley,
Graham, Husbands & Philippides 2012, PLoS Comput Biol 8(1): e1002336, abstract). The
scan, the step and the stop at the targets are shared with ``infomax`` and documented,
with every choice the paper leaves open, in :mod:`homing_baselines.familiarity`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from homing_baselines.familiarity import FamiliarityController, normalised


class PerfectMemory:
    """The training views (grey ``(K, h, w)``, each normalised to zero mean and unit
    variance); :meth:`unfamiliarity` of a view is its smallest RMS difference to any."""

    def __init__(self, views: np.ndarray):
        self.views = normalised(views)                         # (K, n)
        self._norms = (self.views ** 2).sum(axis=1)

    def differences(self, images: np.ndarray) -> np.ndarray:
        """``(S, K)``: RMS difference of each of ``images`` ``(S, h, w)`` to each view
        (``|x|^2 + |v|^2 - 2 x.v`` for all pairs at once)."""
        x = normalised(images)
        ssd = (x ** 2).sum(axis=1)[:, None] + self._norms[None, :] - 2 * x @ self.views.T
        return np.sqrt(np.maximum(ssd, 0.0) / x.shape[1])

    def unfamiliarity(self, images: np.ndarray) -> np.ndarray:
        """``(S,)``: the smallest difference of each image to any stored view."""
        return self.differences(images).min(axis=1)


@dataclass
class PerfectMemoryController(FamiliarityController):
    """Perfect Memory (Baddeley et al. 2012): scan, then step towards the heading whose
    view differs least from any training view. Parameters: those of
    :class:`~homing_baselines.familiarity.FamiliarityController`."""

    def make_memory(self, views: np.ndarray) -> PerfectMemory:
        return PerfectMemory(views)
