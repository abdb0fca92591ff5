"""``random``: a random walk of paper-style moves, the chance-level baseline."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.motion import Move


@dataclass
class RandomController(Controller):
    """Each decision: a direction drawn uniformly from (-pi, pi] and a step of
    ``step_length`` metres. Never stops. Reproducible: the generator is seeded from
    ``seed`` and the episode seed given to :meth:`reset`."""

    step_length: float = 0.2
    seed: int = 0

    def validate(self) -> None:
        if not (math.isfinite(self.step_length) and self.step_length > 0):
            raise ValueError(f"random: step_length must be positive metres, "
                             f"got {self.step_length!r}")
        if not (isinstance(self.seed, (int, np.integer)) and self.seed >= 0):
            raise ValueError(f"random: seed must be an integer >= 0, got {self.seed!r}")

    def on_reset(self) -> None:
        episode = [] if self._seed is None else [int(self._seed)]
        self._rng = np.random.default_rng([int(self.seed), *episode])

    def decide(self, observation) -> Move:
        if not hasattr(self, "_rng"):
            self.on_reset()
        return Move(float(self._rng.uniform(-math.pi, math.pi)), self.step_length)
