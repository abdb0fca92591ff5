"""The poses of one episode."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Episode:
    """The poses ``(x, y, yaw)`` (metres, radians CCW) of one episode: the start, and the
    goals to reach in order, ``waypoints`` first and ``home`` last."""

    home: np.ndarray
    start: np.ndarray
    waypoints: tuple[np.ndarray, ...] = ()

    @property
    def goals(self) -> tuple[np.ndarray, ...]:
        return (*self.waypoints, self.home)
