"""The observation table: every observation key, its space and how it is produced, in one place.

An :class:`ObservationKey` says what a key's ``Box``/``Discrete`` space is (given the
camera settings) and how its value is produced from a :class:`Sight`, the view of one
pose: the current pose at every step, or a goal pose when the goal snapshots are taken at
reset (``goal=True`` entries, produced once per goal and then repeated). The env core's
keys are :data:`CORE_KEYS`; a task adds its own through
:meth:`homing_gym.tasks.Task.observation_keys`. Adding a key touches one place: its entry.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from homing_gym.render.panorama import CameraConfig, PanoramaCamera


class Sight:
    """What the robot's camera and encoders give at one pose.

    ``panorama``: the panorama there (uint8 HWC), rendered when first read;
    ``camera``: the :class:`~homing_gym.render.panorama.PanoramaCamera` (for the ring image and
    the signature derived from a panorama); ``odometry``: the wheel-odometry estimate
    ``(x, y, yaw)`` (metres, radians), or ``None`` for a goal snapshot;
    ``panorama_ahead(d)``: the panorama ``d`` metres straight ahead (goal snapshots only);
    ``view(size, hfov_deg)``: an ordinary perspective view (current pose only);
    ``previous``: the panorama of the step before (current pose only; at the episode's
    first observation, the current panorama)."""

    def __init__(self, camera: PanoramaCamera, render: Callable[[], np.ndarray], *,
                 odometry: Callable[[], np.ndarray] | None = None,
                 ahead: Callable[[float], np.ndarray] | None = None,
                 view: Callable[[tuple[int, int], float], np.ndarray] | None = None,
                 previous: Callable[[], np.ndarray | None] | None = None):
        self.camera = camera
        self._render, self._odometry, self._ahead, self._view = render, odometry, ahead, view
        self._previous = previous
        self._panorama: np.ndarray | None = None

    @property
    def panorama(self) -> np.ndarray:
        if self._panorama is None:
            self._panorama = self._render()
        return self._panorama

    @property
    def odometry(self) -> np.ndarray:
        if self._odometry is None:
            raise ValueError("a goal snapshot has no odometry")
        return self._odometry()

    def panorama_ahead(self, distance: float) -> np.ndarray:
        if self._ahead is None:
            raise ValueError("only a goal snapshot renders the panorama ahead of it")
        return self._ahead(distance)

    def view(self, size: tuple[int, int], hfov_deg: float) -> np.ndarray:
        if self._view is None:
            raise ValueError("only the current pose renders a perspective view")
        return self._view(size, hfov_deg)

    @property
    def previous(self) -> np.ndarray:
        if self._previous is None:
            raise ValueError("a goal snapshot has no previous step")
        before = self._previous()
        return (self.panorama if before is None else before).copy()


@dataclass(frozen=True)
class ObservationKey:
    """One observation key: ``space(camera_config)`` its space, ``produce(sight)`` its value.

    ``goal``: produced from each goal's snapshot at reset (lighting of snapshot time) and
    repeated until the goal changes. ``rendered``: needs a camera image this step (such
    keys are skipped, their last value repeated, after ``HomingEnv.skip_next_images``)."""

    space: Callable[[CameraConfig], spaces.Space]
    produce: Callable[[Sight], np.ndarray]
    goal: bool = False
    rendered: bool = True


def _image(config: CameraConfig) -> spaces.Box:
    return spaces.Box(0, 255, (*config.panorama_shape, 3), np.uint8)


def _ring(config: CameraConfig) -> spaces.Box:
    return spaces.Box(0, 255, (config.omni_size, config.omni_size, 3), np.uint8)


def _signature(config: CameraConfig) -> spaces.Box:
    return spaces.Box(0.0, 1.0, (config.panorama_shape[1],), np.float32)


def _pose(config: CameraConfig) -> spaces.Box:
    return spaces.Box(-np.inf, np.inf, (3,), np.float32)


def _panorama(sight: Sight) -> np.ndarray:
    return sight.panorama.copy()


def _omni(sight: Sight) -> np.ndarray:
    return sight.camera.omni(sight.panorama)


def _signature_of(sight: Sight) -> np.ndarray:
    return sight.camera.signature(sight.panorama)


def goal_step_key(step_length: float) -> ObservationKey:
    """``goal_step``: the snapshot ``step_length`` metres straight ahead of the goal (Yu &
    Kim §II-A measure their nest map from two snapshots one step apart)."""
    if not (math.isfinite(step_length) and 0 < step_length <= 1):
        raise ValueError(f"goal_step_length must be in (0, 1] metres, got {step_length!r}")
    return ObservationKey(_image, lambda sight: sight.panorama_ahead(step_length), goal=True)


#: The env core's keys (``goal_step`` is added with the env's ``goal_step_length``).
CORE_KEYS: dict[str, ObservationKey] = {
    "panorama": ObservationKey(_image, _panorama),
    "omni": ObservationKey(_ring, _omni),
    "signature": ObservationKey(_signature, _signature_of),
    "odometry": ObservationKey(_pose, lambda sight: sight.odometry.astype(np.float32),
                               rendered=False),
    "previous": ObservationKey(_image, lambda sight: sight.previous),
    "goal": ObservationKey(_image, _panorama, goal=True),
    "goal_omni": ObservationKey(_ring, _omni, goal=True),
    "goal_signature": ObservationKey(_signature, _signature_of, goal=True),
}

#: Keys read from the current pose's panorama (one ray-cast image per step).
PANORAMA_KEYS = ("panorama", "omni", "signature", "previous")


def constant_key(space: spaces.Space, value: Callable[[], np.ndarray]) -> ObservationKey:
    """A key whose value a task holds (``value()``), not read from the camera."""
    return ObservationKey(lambda config: space, lambda sight: value(), rendered=False)
