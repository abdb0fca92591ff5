"""``bearing-longrange``: Bekris, Argyros & Kavraki's long-range homing (§3, Fig. 5) with
KLT corner features (§4), for ``homing_gym/LongRangeHoming-v0``.

**Visual memory** (outbound, ``observation["phase"] == 0``; the env drives and ignores the
actions): every frame goes through the KLT tracker (:class:`homing_baselines.klt.CornerTracker`)
and the controller stores, per frame, the ids and positions of the live tracks and the
prepared image. A track never comes back once lost, so a feature's *life cycle* (a line
of Fig. 5) is the run of frames from its birth to its last sighting.

**Milestones** (at the first homing frame ``G``, :func:`choose_milestones`): "how far the
robot can go towards home based on the extracted and tracked features": the next
milestone position (MP) is the *earliest* frame that still shares ``min_shared`` features
with ``G``. Features alive at ``G`` and born at or before frame ``t`` are alive from ``t``
to ``G``, so this is the ``min_shared``-th smallest birth frame among them. Then the same
from that MP, until home (frame 0) is an MP. If not even the previous frame shares
``min_shared`` features (features lost faster than that), the previous frame is taken.

**Homing**, leg by leg: the target snapshot of a leg is the memory's bearings, at the MP,
of the features it shares with the leg's start; the current snapshot is the live tracks
of those features; the unified law (Algorithm 1) gives the motion vector, executed as in
:class:`homing_baselines.bearing.BearingLawController` (the step scales with ``|M|`` per pair, so
it shrinks near the MP with 80 features as with three).

**Arrival and realignment** (§3): at an MP ``P`` the robot stands at ``P'``, the same
place under another heading, so every bearing differs by one constant,
``A_P(F_i) - A_P'(F_i) = phi``, estimated as the median offset. The robot has arrived when
at least ``inlier_fraction`` of the leg's live features lie within ``stop_tol`` of
``phi``: Algorithm 1's "snapshots similar" (:func:`homing_baselines.bearing_laws.snapshots_similar`
with ``aligned=True`` after rotating by ``phi``), made robust to the KLT tracks that drift
onto another corner over a long leg (one would stop the plain test from ever holding). It
then predicts where every feature of the MP's memory frame lies now (shifted by ``phi``)
and re-attaches them by LK from the stored image, starting at the prediction
(:meth:`homing_baselines.klt.CornerTracker.register`: the paper's "feature selection ... in
small windows centred at the predicted locations"; a feature still tracked starts from its
track instead), and starts the next leg. At home it turns by ``-phi`` to the home heading
and stops.

Choices where the paper is open (also in ``docs/bearing.md``):

* ``min_shared`` = 80 of ``KLTConfig.max_features`` = 100, the paper's experiment (at
  least 3 are needed). Fewer shared features give fewer, longer legs; the laws have no
  obstacle avoidance and a long chord across the room can run into a column.
* ``stop_tol`` = 0.01 rad (0.4 of a column of a 256-column panorama) with
  ``inlier_fraction`` = 0.5, i.e. the median residual. 0.02 rad was met up to 15 cm from
  home and 20-40 cm from MPs whose features are all far; 0.01 rad is reached only because
  stalled tracks are registered afresh (next point).
* **Registration when the residual stalls.** KLT tracks drift by a pixel or so over a
  leg, and near an MP the median residual then stays above the tolerance: the robot stood
  1-5 cm from an MP for 1000+ steps (seeds 206, 220). When the median residual has not
  gone below its best of the leg for ``stall_decisions`` (5) decisions, the controller
  applies §3's registration step against the MP's stored image before arriving (the
  paper registers at each MP; here also on the way when the tracks stall), each feature
  starting from its live track, and judges arrival on the registered features.
* Every live feature of the leg steers (all pairs, as in §2-3). Leaving out the features
  whose residual exceeded 3 times the median (against mistracked corners) was withdrawn:
  far from an MP it left out the near features' parallax, the rest no longer surrounded
  the MP, and the robot stepped 1.5-2 rad off course for 900+ steps (seeds 201, 208).
* A leg's feature set shrinks as tracks are lost; Algorithm 1 needs the same landmarks at
  every step, so its state restarts whenever the set changes. With corners all around,
  criterion 1 (goal inside their hull) decides BASIC at once, so little is lost.
* With fewer than three live features of a leg the robot makes the search move of
  :class:`~homing_baselines.bearing.BearingLawController`.

The controller reads ``panorama`` and ``phase`` only (not ``goal``: the home snapshot is
its first memory frame).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar, Sequence

import numpy as np

from homing_baselines.bearing import BearingLawController
from homing_baselines.bearing_laws import UnifiedLaw
from homing_baselines.klt import CornerTracker, KLTConfig
from homing_baselines.motion import Move
from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import column_bearing


@dataclass(frozen=True)
class MemoryFrame:
    """One frame of the visual memory: track ``ids`` ``(n,)``, their ``points``
    ``(n, 2)`` (panorama pixels ``x, y``) and the prepared image (for re-registration)."""

    ids: np.ndarray
    points: np.ndarray
    image: np.ndarray


def birth_frames(frames: Sequence[np.ndarray]) -> dict[int, int]:
    """The frame in which each track id was first seen (the start of its life cycle)."""
    births: dict[int, int] = {}
    for t, ids in enumerate(frames):
        for i in np.asarray(ids).tolist():
            births.setdefault(int(i), t)
    return births


def choose_milestones(frames: Sequence[np.ndarray], min_shared: int) -> list[int]:
    """Milestone frame indices from the last frame back to home (frame 0), from each
    frame's track ids (tracks never come back once lost): each MP is the earliest frame
    that shares at least ``min_shared`` ids with the previous MP, the last frame to start
    with; the previous frame when none does. Ends with 0; empty for a single frame."""
    if len(frames) == 0:
        raise ValueError("the visual memory is empty: no outbound frame was observed")
    if not (isinstance(min_shared, (int, np.integer)) and min_shared >= 1):
        raise ValueError(f"min_shared must be an integer >= 1, got {min_shared!r}")
    births = birth_frames(frames)
    chain, cur = [], len(frames) - 1
    while cur > 0:
        born = np.sort([births[int(i)] for i in np.asarray(frames[cur]).tolist()])
        earliest = int(born[min_shared - 1]) if len(born) >= min_shared else cur
        cur = min(earliest, cur - 1)
        chain.append(cur)
    return chain


def median_offset(offsets: np.ndarray) -> float:
    """§3's ``phi = median{A_P(F_i) - A_P'(F_i)}`` (radians, in ``(-pi, pi]``), taken around
    the offsets' circular mean so that values either side of +-pi do not split."""
    offsets = np.asarray(offsets, dtype=np.float64)
    if offsets.size == 0:
        raise ValueError("median_offset needs at least one offset")
    centre = math.atan2(np.sin(offsets).mean(), np.cos(offsets).mean())
    return float(wrap_angle(centre + float(np.median(wrap_angle(offsets - centre)))))


@dataclass
class LongRangeBearingController(BearingLawController):
    """Long-range homing (module docstring). Parameters: ``min_shared`` (features that
    consecutive milestones share, 3 to ``klt.max_features``), ``inlier_fraction`` (of a
    leg's live features that must agree with ``phi`` to arrive), ``stall_decisions`` (decisions without a new smallest median residual
    after which the leg's features are registered afresh against the MP image), ``klt``
    (:class:`~homing_baselines.klt.KLTConfig`) and those of
    :class:`~homing_baselines.bearing.BearingLawController` (``stop_tol``: the arrival tolerance
    on each feature's offset from ``phi``, radians)."""

    min_shared: int = 80
    inlier_fraction: float = 0.5
    stall_decisions: int = 5
    stop_tol: float = 0.01
    klt: KLTConfig = field(default_factory=KLTConfig)

    envs: ClassVar[tuple[str, ...] | None] = ("homing_gym/LongRangeHoming-v0",)
    scenes: ClassVar[tuple[str, ...] | None] = None      # corners, not colours

    def validate(self) -> None:
        super().validate()
        if not isinstance(self.klt, KLTConfig):
            raise ValueError(f"klt must be a KLTConfig, got {self.klt!r}")
        if not (isinstance(self.min_shared, (int, np.integer))
                and 3 <= self.min_shared <= self.klt.max_features):
            raise ValueError(f"min_shared must be an integer from 3 (the laws need three "
                             f"features) to klt.max_features = {self.klt.max_features}, "
                             f"got {self.min_shared!r}")
        if not 0 < self.inlier_fraction <= 1:
            raise ValueError(f"inlier_fraction must be in (0, 1], got {self.inlier_fraction!r}")
        if not (isinstance(self.stall_decisions, (int, np.integer)) and self.stall_decisions >= 1):
            raise ValueError(f"stall_decisions must be an integer >= 1, got "
                             f"{self.stall_decisions!r}")

    def observation_keys(self) -> tuple[str, ...]:
        return ("panorama", "phase")

    def on_reset(self) -> None:
        self.tracker = CornerTracker(self.klt)
        self.memory: list[MemoryFrame] = []
        #: Memory frame indices of the MPs, from the first to home (0); ``None`` outbound.
        self.milestones: list[int] | None = None
        self.leg = 0
        self.leg_ids = np.zeros(0, dtype=np.int64)
        #: The latest estimate of ``phi`` (radians), ``None`` before the first.
        self.phi: float | None = None
        self._law = UnifiedLaw(self.unified_config())
        self._law_ids = np.zeros(0, dtype=np.int64)
        self._home = False

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """Track every frame (the base class decides only between moves), then act: stop
        actions while the env drives the outbound route, the moves of the legs after."""
        if episode_start is not None and bool(np.any(episode_start)):
            self.reset(self._seed)
        missing = [k for k in self.observation_keys() if k not in observation]
        if missing:
            raise ValueError(f"bearing-longrange needs the observation keys {missing} "
                             f"(LongRangeHoming-v0's obs_keys must include them)")
        self.tracker.update(observation["panorama"])
        if self.milestones is None:
            self.memory.append(MemoryFrame(self.tracker.ids.copy(),
                                           self.tracker.points.copy(), self.tracker.image))
            if int(observation["phase"]) == 0:
                return self._helper.stop_action(), state   # actions ignored outbound
            self.milestones = choose_milestones([f.ids for f in self.memory],
                                                self.min_shared) or [0]
            self._begin_leg(0, len(self.memory) - 1)
        return super().predict(observation, state, None, deterministic)

    # -- legs -----------------------------------------------------------------------------
    def _begin_leg(self, leg: int, origin: int) -> None:
        """Leg ``leg`` goes from memory frame ``origin`` to milestone ``leg``."""
        self.leg = leg
        self._best_median, self._stalled = math.inf, 0
        self.leg_ids = np.intersect1d(self.memory[self.milestones[leg]].ids,
                                      self.memory[origin].ids)

    def _bearings(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Ids, current and milestone bearings (radians) of the leg's live features."""
        target = self.memory[self.milestones[self.leg]]
        live = np.isin(self.tracker.ids, self.leg_ids)
        ids = self.tracker.ids[live]
        row = {int(i): r for r, i in enumerate(target.ids.tolist())}
        x = target.points[[row[int(i)] for i in ids.tolist()], 0]
        return ids, self.tracker.bearings()[live], wrap_angle(column_bearing(x, self.tracker.width))

    def _register(self) -> int:
        """Re-attach the features of milestone ``leg``'s memory frame from its stored image
        (§3's registration): LK starting from each feature's live track where it has one,
        else from its MP column shifted by ``phi``. Returns how many joined."""
        frame = self.memory[self.milestones[self.leg]]
        shift = self.phi * self.tracker.width / (2 * math.pi)   # x' = x + phi W / (2 pi)
        guess = frame.points + np.array([shift, 0.0])
        live = {int(i): r for r, i in enumerate(self.tracker.ids.tolist())}
        rows = [(k, live[int(i)]) for k, i in enumerate(frame.ids.tolist()) if int(i) in live]
        if rows:
            at_mp, now = np.array(rows).T
            guess[at_mp] = self.tracker.points[now]
        return self.tracker.register(frame.image, frame.points, frame.ids, guess)

    def _arrive(self) -> None:
        """At milestone ``leg``: re-attach its frame's features (§3) and start the next
        leg."""
        self._register()
        self._begin_leg(self.leg + 1, self.milestones[self.leg])

    def _residuals(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The leg's live features: ids, current and milestone bearings, and each one's
        offset residual ``|A_P(F_i) - A_P'(F_i) - phi|`` (radians); updates ``phi``."""
        ids, current, target = self._bearings()
        if len(current) < 3:
            return ids, current, target, np.zeros(0)
        offsets = wrap_angle(target - current)
        self.phi = median_offset(offsets)
        return ids, current, target, np.abs(wrap_angle(offsets - self.phi))

    def decide(self, observation: dict[str, np.ndarray]) -> Move | None:
        if self._home:
            return None
        ids, current, target, residual = self._residuals()
        if len(current) < 3:
            return self.search_move()
        median = float(np.median(residual))
        if median < self._best_median:
            self._best_median, self._stalled = median, 0
        else:
            self._stalled += 1
        if self._stalled >= self.stall_decisions \
                and np.mean(residual <= self.stop_tol) < self.inlier_fraction:
            # the tracks have not brought the robot closer for a while: measure the
            # features afresh against the MP's stored image instead of trusting them
            self._register()
            ids, current, target, residual = self._residuals()
            median = float(np.median(residual))
            self._best_median, self._stalled = median, 0
        if np.mean(residual <= self.stop_tol) >= self.inlier_fraction:
            if self.leg == len(self.milestones) - 1:   # home: turn to its heading, stop
                self._home = True
                return Move(float(wrap_angle(-self.phi)), 0.0)
            self._arrive()
            return self.decide(observation)
        if not np.array_equal(ids, self._law_ids):     # features lost or re-attached:
            self._law = UnifiedLaw(self.unified_config())   # Algorithm 1 starts again
            self._law_ids = ids
        result = self._law.step(current, target)
        if not math.isfinite(result.direction):
            return self.search_move()
        return self.move_along(result)
