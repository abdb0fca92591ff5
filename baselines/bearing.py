"""``bearing``, ``bearing-basic``, ``bearing-complementary``: Bekris, Argyros & Kavraki's
bearing-only homing laws (§2) driven by coloured-blob landmarks seen in the panoramas.

Every decision (:meth:`BearingController.decide`):

1. finds the coloured landmarks in the current panorama and in the goal panorama
   (:func:`homing_baselines.blobs.detect_blobs`, §4 "Centroids of colored blobs"; identity by
   colour) and keeps those seen in both, in the order of ``colors``;
2. stops (returns ``None``, the env's stop action) when the two snapshots are similar:
   every angular separation agrees within ``stop_tol`` radians
   (:func:`homing_baselines.bearing_laws.snapshots_similar`, Algorithm 1's "until current
   snapshot A and goal snapshot T are similar");
3. otherwise evaluates the law on the bearings (the basic law Eq. 1-2, the
   complementary law, or the unified law of Algorithm 1, whose state persists through
   the episode) and moves along the motion vector ``M`` (robot frame, CCW).

Choices where the paper is open (also in ``docs/bearing.md``):

* **Step length.** The paper's robot follows ``M`` continuously ("updated over time").
  We move ``gain * |M| * 3 / P`` metres (``|M|`` in radians, Eq. 1; ``P`` the number of
  landmark pairs summed, 3 for three landmarks), clipped to ``[min_step, step_length]`` =
  [0.02, 0.10] m, then decide again: full steps far away, short ones near the goal, where
  ``|M|`` tends to 0. Dividing by ``P / 3`` keeps the step of three landmarks and makes it
  independent of the number of features (``|M|`` sums ``N(N-1)/2`` pairs: 3160 for 80
  KLT corners, where an unscaled step would always be the longest and overshoot).
* **Stop tolerance.** ``stop_tol`` = 0.02 rad (1.15 deg) on every separation. §6 puts the
  accuracy of a separation at 0.027 rad for a 1394-pixel panorama and 3 pixels of
  feature error; our default panorama is 256 columns (1.41 deg each) but the blob
  centroid is sub-pixel, measured at about 0.3 deg mean error in the ``lab`` scene.
* **Unified law timing.** ``UnifiedConfig``'s ``dwell`` and ``trend_steps`` count
  decisions; they are set so that they cover at least the distances of the 2-D
  simulator (20 cm and 5 cm at 1 cm per step) at ``min_step`` per decision (10 and 3
  decisions): on the NLP arc, where criterion 4 is judged, ``|M|`` is small and the
  steps are short. Shorter spans read pixel noise as a trend. Near the arc the law's
  direction often flips back and forth from one decision to the next (the robot steps
  across a curve the field converges onto), and a 3-decision window then reads the
  phase of those steps: ``trend_from="arrival"`` with ``trend_margin`` about the
  separations' noise judges the change since the robot reached the arc instead
  (``docs/bearing.md``, "Homes anywhere in the lab"): the blob controllers' default,
  with 0.01 rad, about twice a separation's noise at 256 columns (``bearing-longrange``
  keeps the window).
* **Backing up.** ``motion="reversing"`` (:mod:`homing_baselines.motion`), the blob
  controllers' default, drives a direction behind the robot backwards instead of turning
  round first: the paper's robot follows ``M`` continuously, where ours spent up to 20
  actions on each half turn.
* **A landmark hidden behind another column** (:meth:`BearingController.bearings_with_occluded`):
  the paper's tracker "was able to recapture the landmark as soon as it reappeared"
  (§5) but the paper does not say what the robot does meanwhile. A landmark missing now
  that was within ``occlusion_gap`` radians of a landmark seen now, at the last decision
  that saw all of them, lies behind that column and takes its bearing (error below the
  column's half-width). In the goal snapshot a single missing landmark is put behind the
  widest (nearest) column seen (:func:`goal_bearings`): only a nearer column can hide it.
* **Going round a near column** (:meth:`BearingController.around_columns`): the laws
  treat landmarks as points, and the straight way to a goal can run through a column
  (the paper's panels were out of the robot's way; §5: the law resumes "as soon as the
  interrupting process completed"). A column whose blob spans at least ``near_width``
  radians and more than in the goal snapshot, with the move heading towards it, is
  stepped round perpendicular to its bearing, on the move's side.
* **Fewer than three landmarks** even then (one out of sight for another reason): the
  laws need three, so the robot continues along its last direction by ``min_step`` (or
  turns by 90 degrees on the spot if it has none yet) and looks again.

The controller reads ``panorama`` and ``goal`` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.bearing_laws import (LAWS, LawResult, UnifiedConfig, UnifiedLaw, basic_law,
                                    complementary_law, snapshots_similar)
from homing_baselines.blobs import LAB_COLORS, Blob, BlobColor, detect_blobs
from homing_baselines.motion import Move
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_positive

#: Landmark colours a controller may use, by name.
PALETTE: dict[str, BlobColor] = {c.name: c for c in LAB_COLORS}


@dataclass
class BearingLawController(Controller):
    """What every controller driven by the laws of §2 shares: the step along ``M`` and the
    unified law's timing (module docstring). ``step_length`` and ``min_step`` (metres),
    ``gain`` (metres per radian of ``|M|``), ``stop_tol`` (radians); ``trend_from`` and
    ``trend_margin`` (radians): how criterion 4 reads a trend (:class:`UnifiedConfig`)."""

    step_length: float = 0.10
    min_step: float = 0.02
    gain: float = 0.3
    stop_tol: float = 0.02
    trend_from: str = "window"
    trend_margin: float = 0.0

    #: Landmarks are identified by colour: the shipped scene with three distinctly
    #: coloured landmarks is ``lab`` (the ``arena``'s four red cylinders are one colour).
    scenes: ClassVar[tuple[str, ...] | None] = ("lab",)

    def validate(self) -> None:
        if not (math.isfinite(self.min_step) and 0 < self.min_step <= self.step_length):
            raise ValueError(f"need 0 < min_step <= step_length metres, got "
                             f"min_step={self.min_step!r}, step_length={self.step_length!r}")
        if not (math.isfinite(self.step_length) and self.step_length <= 1.0):
            raise ValueError(f"step_length must be at most 1 metre, got {self.step_length!r}")
        for name in ("gain", "stop_tol"):
            value = getattr(self, name)
            require_positive(name, value)
        self.unified_config()      # ValueError naming a bad trend_from or trend_margin

    def unified_config(self) -> UnifiedConfig:
        """Algorithm 1's settings at this controller's step length (module docstring)."""
        return UnifiedConfig(dwell=max(1, math.ceil(0.2 / self.min_step)),
                             trend_steps=max(1, math.ceil(0.05 / self.min_step)),
                             stop_tol=self.stop_tol, trend_from=self.trend_from,
                             trend_margin=self.trend_margin)

    def move_along(self, result: LawResult) -> Move:
        """The step along the law's motion vector (length ``gain * |M| * 3 / P``, clipped;
        ``P`` pairs)."""
        size = float(np.hypot(*result.vector)) * 3 / len(result.pairs)
        return Move(result.direction, min(self.step_length, max(self.min_step, self.gain * size)))

    def search_move(self) -> Move:
        """The move when fewer than three landmarks are matched: straight ahead (the last
        direction) by ``min_step``, or a quarter turn on the spot before any move."""
        if self.last_direction is None:
            return Move(math.pi / 2, 0.0)
        return Move(self.last_travel or 0.0, self.min_step)


@dataclass
class BearingController(BearingLawController):
    """Bearing-only homing from coloured blobs (module docstring). Parameters: ``colors``
    (names in :data:`PALETTE`, at least 3), ``min_area`` (pixels of a blob),
    ``occlusion_gap`` (radians: how near a column a landmark must have been to be taken
    as hidden behind it), ``near_width`` (radians: the blob width from which a column is
    near, 0.45 rad = about 0.45 m for the lab's 0.1 m columns) and those of
    :class:`BearingLawController`, with ``motion="reversing"`` and criterion 4 judged from
    the arc's arrival beyond ``trend_margin`` = 0.01 rad (module docstring). The law is
    the class's ``law``: ``unified`` here."""

    colors: tuple[str, ...] = ("red", "green", "blue")
    min_area: int = 4
    occlusion_gap: float = 0.5
    near_width: float = 0.45
    motion: str = "reversing"
    trend_from: str = "arrival"
    trend_margin: float = 0.01

    law: ClassVar[str] = "unified"
    reads_at_decisions_only: ClassVar[bool] = True

    def validate(self) -> None:
        super().validate()
        if self.law not in LAWS:
            raise ValueError(f"unknown law {self.law!r}; allowed: {LAWS}")
        unknown = ([self.colors] if isinstance(self.colors, str)
                   or not isinstance(self.colors, (list, tuple))
                   else [c for c in self.colors if c not in PALETTE])
        if unknown or len(set(self.colors)) < 3 or len(set(self.colors)) != len(self.colors):
            raise ValueError(f"colors must be at least 3 distinct names from "
                             f"{sorted(PALETTE)}, got {self.colors!r}")
        if not (isinstance(self.min_area, (int, np.integer)) and self.min_area >= 1):
            raise ValueError(f"min_area must be an integer >= 1 pixels, got {self.min_area!r}")
        for name in ("occlusion_gap", "near_width"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0 < value < math.pi):
                raise ValueError(f"{name} must be in (0, pi) radians, got {value!r}")

    def on_reset(self) -> None:
        self._unified = UnifiedLaw(self.unified_config())
        self.last_result: LawResult | None = None
        self._all_seen: dict[str, float] | None = None
        self._detour: dict[str, float] = {}

    def evaluate(self, current: np.ndarray, goal: np.ndarray) -> LawResult:
        """This controller's law on matched bearings (radians, CCW)."""
        if self.law == "basic":
            return basic_law(current, goal)
        if self.law == "complementary":
            return complementary_law(current, goal)
        return self._unified.step(current, goal)

    def decide(self, observation: dict[str, np.ndarray]) -> Move | None:
        palette = tuple(PALETTE[c] for c in self.colors)
        now = detect_blobs(observation["panorama"], palette, self.min_area)
        then = detect_blobs(observation["goal"], palette, self.min_area)
        seen = self.bearings_with_occluded(now)
        target = goal_bearings(then, self.colors)
        both = [c for c in self.colors if c in seen and c in target]
        if len(both) < 3:
            return self.search_move()
        current = np.array([seen[c] for c in both])
        goal = np.array([target[c] for c in both])
        if snapshots_similar(current, goal, self.stop_tol):
            return None
        result = self.evaluate(current, goal)
        self.last_result = result
        if not math.isfinite(result.direction):
            return None
        return self.around_columns(self.move_along(result), now, then)

    def bearings_with_occluded(self, now: dict[str, Blob]) -> dict[str, float]:
        """Bearings (radians) of the landmarks seen now, and of those hidden behind another
        landmark's column: a landmark that was within ``occlusion_gap`` radians of a
        landmark seen now, at the last decision that saw every colour, and is missing now
        lies behind that column, so it takes the column's bearing (error below the
        column's half-width). Remembers the bearings when every colour is seen."""
        seen = {name: blob.bearing for name, blob in now.items()}
        if len(seen) == len(self.colors):
            self._all_seen = seen
            return seen
        last = self._all_seen
        for name in (c for c in self.colors if c not in now and last is not None):
            gaps = {k: abs(wrap_angle(last[name] - last[k])) for k in now}
            if gaps and min(gaps.values()) <= self.occlusion_gap:
                seen[name] = now[min(gaps, key=gaps.get)].bearing
        return seen

    def around_columns(self, move: Move, now: dict[str, Blob], then: dict[str, Blob]) -> Move:
        """``move``, or a step round a landmark column in its way: when a column spans at
        least ``near_width`` radians (it is near), more than it spans in the goal snapshot
        (the goal is farther from it), and ``move`` has a component towards it, the
        robot steps perpendicular to the column's bearing, on the side of ``move`` (kept
        while the same column blocks), so it goes round the column instead of into it."""
        for name, blob in now.items():
            off = float(wrap_angle(move.direction - blob.bearing))
            goal_width = then[name].width if name in then else 0.0
            if blob.width >= max(self.near_width, goal_width) and abs(off) < math.pi / 2:
                side = self._detour.get(name) or math.copysign(1.0, off)
                self._detour = {name: side}
                return Move(float(wrap_angle(blob.bearing + side * math.pi / 2)), move.distance)
        self._detour = {}
        return move


def goal_bearings(goal: dict[str, Blob], colors: tuple[str, ...]) -> dict[str, float]:
    """Bearings (radians) of the goal snapshot's landmarks. When exactly one colour is
    missing and the others are seen, it is taken to be hidden behind the widest (nearest)
    column seen, and takes that column's bearing: only a nearer column can hide it."""
    bearings = {name: blob.bearing for name, blob in goal.items()}
    missing = [c for c in colors if c not in goal]
    if len(missing) == 1 and len(goal) >= 2:
        bearings[missing[0]] = max(goal.values(), key=lambda b: b.width).bearing
    return bearings


@dataclass
class BasicBearingController(BearingController):
    """``bearing-basic``: the basic law (Eq. 1-2) from coloured blobs."""

    law: ClassVar[str] = "basic"


@dataclass
class ComplementaryBearingController(BearingController):
    """``bearing-complementary``: the complementary law (§2) from coloured blobs."""

    law: ClassVar[str] = "complementary"
