"""``did``: descent in image distance, Zeil, Hofmann & Chahl (2003), with the RIDF compass.

"Catchment areas of panoramic snapshots in outdoor scenes", J. Opt. Soc. Am. A 20(3):
450-469. The paper measures how the difference between a panorama taken at a place and a
reference panorama grows with the distance between the two places, and shows that a
robot can find the reference place by moving so that this difference decreases. The
pieces, as the paper defines them:

* **Image difference function (IDF)**: the root-mean-square pixel difference
  ``d(x) = sqrt( 1/(M N) * sum_{i,j} (I_x(i, j) - I_ref(i, j))^2 )`` of the two
  ``M x N`` panoramas (:func:`rms_difference`).
* **Rotational image difference function (RIDF)**: the same difference with the current
  panorama rotated in azimuth by every column shift; its minimum is at the rotation that
  best aligns the two views (the paper's rotational difference functions: deep minimum at
  the reference orientation, little change with distance from the reference place), i.e.
  a *visual compass* (:func:`rotational_idf`, :func:`visual_compass`). The IDF used for the
  descent is the RIDF's minimum, which does not depend on the robot's heading.
* **Descent**: the paper shows that simple gradient-descent schemes recover the goal
  from starts within the catchment area (its homing experiments on the image grids:
  "simple gradient descent methods are surprisingly successful", abstract). It analyses
  the IDF rather than prescribing one controller for a robot; the follow-up literature
  (Möller & Vardy 2006, Biol. Cybern. 95: "to compute an estimate of the spatial gradient
  in the distance measure, its value must be sampled at three noncollinear points")
  states the minimum a gradient estimate needs.

Our controller (choices where the paper prescribes nothing, each with its reason):

* **Three-point gradient** ("triangle" scheme): at a base point ``P0`` the robot measures
  the IDF, drives ``probe_length`` straight ahead to ``P1`` (no turn: the cheapest test
  move), turns a quarter turn left and drives ``probe_length`` to ``P2``, measuring the IDF at
  each. The plane through the three samples gives the gradient ``g``; the robot then moves
  from ``P2`` along ``-g``. Three non-collinear samples are the fewest that determine a
  2-D gradient; the probes are short so that the plane is a local estimate.
* **Frames**: sample positions are dead-reckoned from the commanded moves, their
  directions put in the home (snapshot) frame with the RIDF compass at each decision, so
  the gradient is in the home frame and the move in the robot frame is
  ``angle(-g) - psi`` (``psi``: the compass rotation now). The compass is the paper's RIDF;
  no other heading sensor is observed (the env has no compass key; ``odometry`` starts at
  the start pose and says nothing about the home heading).
* **Step length**: near a sharp minimum the IDF grows about linearly with distance (the
  paper's cone-like difference functions), so ``d / |g|`` estimates the distance to the
  minimum; the descent step is ``min(step_length, descent_gain * d / |g|)``, at least
  ``min_step``.
* **Stop**: when the RIDF minimum is a small fraction of the RIDF's median,
  ``d / median_k RIDF(k) < stop_ratio``: the aligned views differ little compared with
  how much any two unaligned views of this scene differ (a scale-free ratio, so the same
  threshold holds in bright and dark scenes; in the arena it grows about linearly,
  0.19 at 0.05 m, 0.33 at 0.1 m, 0.45 at 0.15 m from home, averaged over 36 rendered
  pairs). After ``max_cycles`` gradient cycles it stops too (a safety limit of ours).
* **Backtracking**: a descent step that ends higher on the IDF than the best sample so
  far halves the following steps (the minimum was overshot).
* **Image**: the panorama's luminance reduced ``levels`` times by a Gaussian pyramid
  (default 2: 48 x 256 -> 12 x 64, 5.6 deg per pixel). The paper uses grey-level panoramas;
  low-pass filtering widens the catchment area and smooths the IDF (Stürzl & Zeil 2007,
  Biol. Cybern. 96, "Depth, contrast and view-based homing in outdoor scenes"); in our
  arena the unfiltered IDF is ragged beyond 0.1 m and its minimum rises where the robot's
  rotation falls between columns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.motion import Move
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_number, require_positive
from homing_gym.vision import low_resolution, luminance


def grey_panorama(panorama: np.ndarray, levels: int = 0) -> np.ndarray:
    """Luminance ``(H, W)`` float64 in ``[0, 1]`` of an RGB uint8 panorama, reduced
    ``levels`` times by a seamless Gaussian pyramid (:func:`homing_gym.vision.low_resolution`).
    A 2-D float array is taken as a grey image already in ``[0, 1]`` (and not reduced)."""
    image = np.asarray(panorama)
    if image.ndim == 2:
        return image.astype(np.float64)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"panorama must be (H, W, 3) RGB or (H, W) grey, got {image.shape}")
    if levels:
        return low_resolution(image, levels).astype(np.float64) / 255.0
    return luminance(image).astype(np.float64)


def rms_difference(a: np.ndarray, b: np.ndarray) -> float:
    """Zeil et al. 2003 IDF: root-mean-square pixel difference of two equal-shape images."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    if a.shape != b.shape:
        raise ValueError(f"images must have the same shape, got {a.shape} and {b.shape}")
    return float(np.sqrt(np.mean((a - b) ** 2)))


def rotational_idf(current: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """RIDF: ``out[k]`` is the RMS difference between ``goal`` and ``current`` rotated by
    ``k`` columns, ``np.roll(current, -k, axis=1)``, for every ``k`` in ``[0, W)``.

    Column ``x`` has bearing ``pi - 2 pi x / W``: a robot turned left by ``psi`` sees the
    goal view's content ``k = psi W / (2 pi)`` columns further right, so the minimum over
    ``k`` is at that rotation. All shifts at once by circular correlation (FFT):
    ``SSD(k) = |c|^2 + |g|^2 - 2 sum_x c[x + k] g[x]``."""
    c, g = grey_panorama(current), grey_panorama(goal)
    if c.shape != g.shape:
        raise ValueError(f"current and goal must have the same shape, got {c.shape} and "
                         f"{g.shape}")
    W = c.shape[1]
    corr = np.fft.irfft((np.fft.rfft(c, axis=1) * np.conj(np.fft.rfft(g, axis=1))).sum(0),
                        n=W)
    ssd = (c ** 2).sum() + (g ** 2).sum() - 2 * corr
    return np.sqrt(np.maximum(ssd, 0.0) / c.size)


def visual_compass(current: np.ndarray, goal: np.ndarray) -> tuple[float, float, float]:
    """The RIDF minimum: ``(psi, d, median)``, ``psi`` the rotation of the robot relative
    to the goal view's heading (radians, counter-clockwise, one column resolution), ``d``
    the rotation-invariant image difference there and ``median`` the RIDF's median over
    all rotations (the difference of unaligned views, a scale for ``d``)."""
    ridf = rotational_idf(current, goal)
    k = int(np.argmin(ridf))
    return wrap_angle(2 * np.pi * k / ridf.size), float(ridf[k]), float(np.median(ridf))


def plane_gradient(points: np.ndarray, values: np.ndarray) -> np.ndarray | None:
    """Gradient ``(gx, gy)`` of the plane through three samples ``values`` at 2-D
    ``points`` (3, 2); ``None`` when the points are (nearly) collinear."""
    p = np.asarray(points, np.float64)
    v = np.asarray(values, np.float64)
    A = p[1:] - p[0]
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    if abs(det) < 1e-9 * max(1e-12, float(np.abs(A).max()) ** 2):
        return None
    return np.linalg.solve(A, v[1:] - v[0])


@dataclass
class DIDController(Controller):
    """Descent in the RMS image difference (Zeil et al. 2003) with the RIDF visual compass
    (see the module doc). Lengths in metres.

    ``probe_length``: each of the two test moves; ``step_length``: the longest descent
    step; ``min_step``: the shortest; ``descent_gain``: the fraction of the estimated
    distance ``d / |g|`` a descent step covers; ``stop_ratio``: stop when the RIDF minimum
    is below this fraction of the RIDF median; ``levels``: pyramid reductions of the
    panorama; ``max_cycles``: gradient cycles before it stops (safety)."""

    #: probes are not home moves: the home direction is set by the descent steps only
    moves_home: ClassVar[bool] = False

    probe_length: float = 0.05
    step_length: float = 0.25
    min_step: float = 0.03
    descent_gain: float = 0.8
    stop_ratio: float = 0.2
    levels: int = 2
    max_cycles: int = 30

    def validate(self) -> None:
        require_positive("did: probe_length", self.probe_length, "metres")
        require_positive("did: step_length", self.step_length, "metres")
        require_positive("did: min_step", self.min_step, "metres")
        if self.min_step > self.step_length:
            raise ValueError(f"did: min_step ({self.min_step!r}) must not exceed step_length "
                             f"({self.step_length!r}) metres")
        require_number("did: descent_gain", self.descent_gain, 0, 2, low_open=True)
        require_number("did: stop_ratio", self.stop_ratio, 0, 1)
        require_number("did: levels", self.levels, 0, 5, "pyramid reductions", integer=True)
        require_number("did: max_cycles", self.max_cycles, 1, 10_000, integer=True)

    def on_reset(self) -> None:
        self._goal_grey: np.ndarray | None = None
        self._new_target()

    def _new_target(self) -> None:
        self._phase = 0                       # 0: base point, 1: after probe 1, 2: after probe 2
        self._position = np.zeros(2)          # dead-reckoned, home-frame directions
        self._samples: list[tuple[np.ndarray, float]] = []
        self._best = math.inf
        self._scale = 1.0                     # halved after each overshoot
        self._cycles = 0
        self._stopped = False
        self.last_distance_estimate: float | None = None
        self.last_compass: float | None = None
        self.last_difference: float | None = None

    def _go(self, direction: float, length: float, psi: float) -> Move:
        """A move in robot-frame ``direction``; its displacement is added to the
        dead-reckoned position in the home frame (compass ``psi``)."""
        heading = psi + direction
        self._position = self._position + length * np.array([math.cos(heading),
                                                             math.sin(heading)])
        return Move(wrap_angle(direction), float(length))

    def decide(self, observation) -> Move | None:
        goal = observation["goal"]
        if self.is_new_goal(goal):              # a new target (a route's next)
            self._goal_grey = grey_panorama(goal, self.levels)
            self._new_target()
        if self._stopped:
            return None
        psi, d, median = visual_compass(grey_panorama(observation["panorama"], self.levels),
                                        self._goal_grey)
        self.last_compass, self.last_difference = psi, d
        if d < self.stop_ratio * median or (self._phase == 0
                                            and self._cycles >= self.max_cycles):
            self._stopped = True
            return None
        here = self._position.copy()
        if self._phase == 0:
            if self._cycles > 0 and d >= self._best:   # a descent step overshot
                self._scale *= 0.5
            self._best = min(self._best, d)
            self._samples = [(here, d)]
            self._phase = 1
            return self._go(0.0, self.probe_length, psi)
        if self._phase == 1:
            self._samples.append((here, d))
            self._best = min(self._best, d)
            self._phase = 2
            return self._go(np.pi / 2, self.probe_length, psi)
        # phase 2: the gradient from the triangle, then the descent step
        self._samples.append((here, d))
        self._best = min(self._best, d)
        self._phase = 0
        self._cycles += 1
        points = np.stack([p for p, _ in self._samples])
        grad = plane_gradient(points, np.array([v for _, v in self._samples]))
        if grad is None or not np.all(np.isfinite(grad)) or np.hypot(*grad) == 0:
            return self._go(0.0, self.min_step, psi)          # degenerate: try elsewhere
        estimate = d / float(np.hypot(*grad))
        self.last_distance_estimate = estimate
        length = float(np.clip(self._scale * self.descent_gain * estimate, self.min_step,
                               self.step_length))
        direction = math.atan2(-grad[1], -grad[0]) - psi
        self.last_home_direction = wrap_angle(direction)
        return self._go(direction, length, psi)
