"""Shiraishi & Sawasaki's multi-resolution image matching navigation (controller
``multires``).

Three phases (§3, Fig. 1), from the observation only (the current panorama and the data
taught on the teaching day, keys of ``WorkLocations-v0``):

1. **Travel** (§3(1)): the current panorama is reduced to the taught low resolution
   and its front (``front_fov_deg`` wide) correlated with every panorama of the path
   (:func:`~homing_baselines.multires_matching.locate_on_path`); the best is the current place,
   its offset the deviation from the desired direction of travel. The robot turns by
   minus the deviation and drives ``step_length`` (the paper's dolly was pushed "while
   the traveling direction is continuously adjusted to maintain a zero deviation").
2. **Arrival decision** (§3(1), Fig. 5): once the best place is the path's last (the
   target work location), the front image is enlarged or reduced through ``scales`` and
   compared with the target's panorama (:func:`~homing_baselines.multires_matching.arrival_scores`):
   enlarged best, not yet there: forward ``arrival_step``; reduced best, past it:
   backward; unscaled best: approximately at the work location.
3. **Work location** (§3(2)): self-localisation with the multiresolution feature image
   map (:func:`~homing_baselines.multires_localise.localise`); the robot drives to the taught
   position while it is more than ``stop_tolerance`` away (problem (a): "errors must be
   visually detected so the robot can reach the specified location with sufficient
   accuracy"), turns to the taught heading, and stops. If fewer than two
   characteristic points are found it stops where the arrival decision left it.

Backward fine-tuning needs continuous actions (negative forward speed); with discrete
actions the controller raises ``ValueError`` at ``configure``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.motion import MotionSpec, Move
from homing_baselines.multires_localise import LocaliseConfig, localise
from homing_baselines.multires_matching import arrival_scores, front_view, locate_on_path
from homing_gym import TAUGHT_KEYS
from homing_gym.geometry import to_frame
from homing_gym.teaching import FeatureMap
from homing_gym.validation import require_positive
from homing_gym.vision import grey, low_resolution

TRAVEL, ARRIVE, LOCALISE = "travel", "arrive", "localise"


@dataclass
class MultiResController(Controller):
    """Parameters: ``front_fov_deg`` (width of the front image, degrees),
    ``step_length`` (m per travel decision), ``scales`` (enlargement factors of the
    arrival decision, must include 1), ``arrival_step`` (m per fine-tuning move),
    ``max_arrival_moves``, ``stop_tolerance`` (m), ``heading_tolerance_deg``,
    ``max_corrections`` (localise-and-move cycles at the work location),
    ``camera_height`` (m) and ``vfov_deg`` (the camera's calibration)."""

    front_fov_deg: float = 60.0
    step_length: float = 0.15
    scales: tuple[float, ...] = field(
        default_factory=lambda: tuple(float(2 ** (k / 16)) for k in range(-4, 5)))
    arrival_step: float = 0.05
    max_arrival_moves: int = 12
    stop_tolerance: float = 0.03
    heading_tolerance_deg: float = 3.0
    max_corrections: int = 8
    camera_height: float = 0.30
    vfov_deg: float = 60.0

    envs: ClassVar[tuple[str, ...] | None] = ("homing_gym/WorkLocations-v0",)
    privileged: ClassVar[str] = ("the taught maps' 3-D feature points and target poses, "
                                 "from the scene (map_points, map_pose)")

    def validate(self) -> None:
        if not (5 <= self.front_fov_deg <= 180):
            raise ValueError(f"front_fov_deg must be in [5, 180] degrees, got {self.front_fov_deg!r}")
        if not (10 <= self.vfov_deg <= 120):      # the env's camera takes the same range
            raise ValueError(f"vfov_deg must be in [10, 120] degrees, got {self.vfov_deg!r}")
        if not (0 < self.heading_tolerance_deg < 180):
            raise ValueError(f"heading_tolerance_deg must be in (0, 180) degrees, got "
                             f"{self.heading_tolerance_deg!r}")
        for name in ("step_length", "arrival_step", "stop_tolerance", "camera_height"):
            value = getattr(self, name)
            require_positive(name, value, "metres")
        if 1.0 not in self.scales or not all(0.5 <= s <= 2 for s in self.scales):
            raise ValueError(f"scales must lie in [0.5, 2] and include 1, got {self.scales!r}")
        for name in ("max_arrival_moves", "max_corrections"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 0):
                raise ValueError(f"{name} must be an integer >= 0, got {value!r}")

    def observation_keys(self) -> tuple[str, ...]:
        return ("panorama", *TAUGHT_KEYS)

    def configure(self, spec: MotionSpec) -> None:
        if spec.action_type != "continuous":
            raise ValueError("multires fine-tunes backwards and needs action_type="
                             f"'continuous', got {spec.action_type!r}")
        super().configure(spec)

    def on_reset(self) -> None:
        self.phase = TRAVEL
        self.place = 0
        self.arrival_moves = 0
        self.corrections = 0
        self._reverse = False
        self.last_localisation = None

    # -- the three phases ------------------------------------------------------------------
    def decide(self, observation: dict[str, np.ndarray]) -> Move | None:
        self._reverse = False
        panorama = observation["panorama"]
        path = observation["path_panoramas"][:int(observation["path_count"])]
        levels = int(round(math.log2(panorama.shape[1] / path.shape[2])))
        low = low_resolution(panorama, levels)
        front = front_view(low, math.radians(self.front_fov_deg))
        if self.phase == TRAVEL:
            self.place, deviation, _ = locate_on_path(front, path)
            if self.place < len(path) - 1:
                return Move(-deviation, self.step_length)
            self.phase = ARRIVE
        if self.phase == ARRIVE:
            move = self._arrive(panorama, front, path[-1], levels)
            if move is not None:
                return move
            self.phase = LOCALISE
        return self._at_work_location(panorama, observation, levels)

    def _arrive(self, panorama, front, target, levels: int) -> Move | None:
        """Fig. 5: a fine-tuning move, or ``None`` once approximately arrived."""
        if self.arrival_moves >= self.max_arrival_moves:
            return None
        _, deviation, _ = locate_on_path(front, [target])
        if abs(deviation) > 2 * math.pi / target.shape[1]:      # face the target first
            self.arrival_moves += 1
            return Move(-deviation, 0.0)
        scores = arrival_scores(grey(panorama), target, self.scales,
                                math.radians(self.front_fov_deg), levels)
        best = self.scales[int(np.argmax(scores))]
        if best == 1.0:
            return None
        self.arrival_moves += 1
        self._reverse = best < 1.0
        return Move(0.0, self.arrival_step)

    def _at_work_location(self, panorama, observation, levels: int) -> Move | None:
        n = int(observation["map_count"])
        fmap = FeatureMap(observation["map_panorama"], observation["map_templates"][:n],
                          observation["map_template_xy"][:n], observation["map_points"][:n],
                          observation["map_pose"].astype(np.float64), levels)
        config = LocaliseConfig(camera_height=self.camera_height,
                                vfov=math.radians(self.vfov_deg))
        result = localise(panorama, fmap, config)
        self.last_localisation = result
        if result.pose is None or self.corrections >= self.max_corrections:
            return None
        self.corrections += 1
        dx, dy, dyaw = to_frame(result.pose, fmap.pose)
        if math.hypot(dx, dy) > self.stop_tolerance:
            return Move(math.atan2(dy, dx), math.hypot(dx, dy))
        if abs(dyaw) > math.radians(self.heading_tolerance_deg):
            return Move(float(dyaw), 0.0)
        return None

    # -- backward moves ----------------------------------------------------------------------
    def predict(self, observation: dict[str, np.ndarray], state: Any = None,
                episode_start: Any = None, deterministic: bool = True) -> tuple[Any, Any]:
        """As :meth:`Controller.predict`; a backward fine-tuning move is the planned
        forward drive with its speed negated."""
        deciding = not self._queue or (episode_start is not None and bool(np.any(episode_start)))
        action, state = super().predict(observation, state, episode_start, deterministic)
        if deciding and self._reverse:
            flip = np.array([-1.0, 1.0], np.float32)
            action = action * flip
            self._queue = [a * flip for a in self._queue]
        return action, state
