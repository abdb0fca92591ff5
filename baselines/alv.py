"""``alv``: the average landmark vector model, Lambrinos, Möller, Labhart, Pfeifer & Wehner (2000).

"A mobile robot employing insect strategies for navigation", Robotics and Autonomous
Systems 30: 39-64, the section on the average landmark vector (ALV) model (the parsimonious
relative of the snapshot model in the same paper, tested there on the Sahabot 2 and in
Möller's analog robot). The model:

* the robot segments landmarks from its panoramic view: dark landmarks against the bright
  background (the paper's landmarks were black cylinders seen against sky and ground);
* each landmark ``i`` contributes the unit vector ``l_i = (cos theta_i, sin theta_i)``
  towards it (``theta_i`` its bearing); the *average landmark vector* is
  ``ALV(x) = (1/n) sum_i l_i`` in a compass-aligned (world) frame;
* at home only ``ALV(home)`` is stored (one vector instead of a snapshot); elsewhere the
  home vector is ``h = ALV(x) - ALV(home)``, which points home: moving by ``dx`` changes
  each ``l_i`` by ``-(I - l_i l_i^T) dx / r_i``, so ``ALV(x) - ALV(home)`` is minus a
  positive semi-definite matrix times ``x - home``.

The vectors must be summed in one frame: the Sahabot 2 used a polarisation compass. Our
robot has no compass observation (the env's keys are images and ``odometry``, which starts
at the start pose and knows nothing of the home heading), so, our choice, the current
view is aligned with the home snapshot by the rotation that minimises the image
difference: the rotational image difference function of Zeil et al. 2003
(:func:`homing_baselines.did.visual_compass`), a *visual compass*. The ALV of the current
view is rotated by that ``psi`` into the home frame; the home direction in the robot
frame is then ``angle(h) - psi``.

The visual compass is biased by parallax away from home (in the arena, rendered pairs
0.4 m apart give errors of 20-70 deg: four alike cylinders in a square room), and a new
error at every decision makes the path wander. So, with the ``odometry`` observation (the
wheel-encoder yaw, relative to the start pose), the compass is the odometry yaw plus an
offset, and the offset is taken from the visual compass at the decision whose views
matched best so far (the lowest ratio of the RIDF minimum to its median, i.e. the most
reliable alignment, which improves as the robot nears home): a compass tracked by the
robot's own encoders and re-anchored visually. Without ``odometry`` in the observation
(``obs_keys`` without it) every decision uses the visual compass alone.

Our other choices (the paper's vision was a thresholded horizon ring of a specific camera):

* Landmarks: the horizon signature (luminance of ``rows`` rows about the horizon on a
  ``n_samples`` bearing grid, :func:`homing_baselines.signature.signature_from_panorama`)
  thresholded at Otsu's level (the threshold that best separates the ring's two
  brightness classes; the paper's images had a fixed threshold between black landmarks
  and bright background, which does not carry over to scenes of other brightness).
  ``polarity="dark"`` takes the runs below the threshold (the paper's dark landmarks),
  ``"bright"`` the runs above, ``"both"`` both. Runs narrower than ``min_width`` degrees are
  noise. A ring with less contrast than ``min_contrast`` has no landmarks.
* The landmark bearing is the circular centre of its run (the paper's landmark vectors
  point to the landmark, i.e. the sector's centre).
* Motion: ``step_length`` m towards ``h``; stop when ``|h| < stop_length`` (unit-vector
  units; in the arena ``|h|`` is about 0.5 per metre near home), or when no landmark is
  seen (no home vector), or after ``max_steps`` (a safety limit of ours).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

from homing_baselines.base import Controller
from homing_baselines.did import grey_panorama, visual_compass
from homing_baselines.motion import Move
from homing_baselines.signature import bearing_grid, signature_from_panorama
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_number, require_positive

POLARITIES = ("dark", "bright", "both")


@dataclass(frozen=True)
class ALVConfig:
    """Landmark segmentation of the ALV model (see the module doc)."""

    n_samples: int = 360
    rows: int = 5
    polarity: str = "dark"
    min_width: float = 2.0
    min_contrast: float = 0.1

    def __post_init__(self) -> None:
        require_number("ALVConfig: n_samples", self.n_samples, 16, 100_000, integer=True)
        require_number("ALVConfig: rows", self.rows, 1, 1000, integer=True)
        if self.polarity not in POLARITIES:
            raise ValueError(f"ALVConfig: polarity must be one of {POLARITIES}, "
                             f"got {self.polarity!r}")
        require_number("ALVConfig: min_width", self.min_width, 0, 180, "degrees")
        require_number("ALVConfig: min_contrast", self.min_contrast, 0, 1)


@dataclass
class Landmarks:
    """Segmented landmarks of one view: bearings (radians, robot frame, CCW), widths
    (radians), the threshold and the ring it came from."""

    bearings: np.ndarray
    widths: np.ndarray
    threshold: float
    ring: np.ndarray = field(repr=False)


def otsu_threshold(values: np.ndarray) -> float:
    """Otsu's threshold of values in ``[0, 1]`` (OpenCV on 256 grey levels)."""
    levels = np.clip(np.asarray(values, np.float64) * 255 + 0.5, 0, 255).astype(np.uint8)
    level, _ = cv2.threshold(levels.reshape(1, -1), 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    return float(level) / 255.0


def circular_runs(mask: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the maximal runs of True in a circular boolean ring."""
    mask = np.asarray(mask, bool)
    n = mask.size
    if mask.all():
        return [np.arange(n)]
    if not mask.any():
        return []
    start = int(np.flatnonzero(~mask)[0])            # begin at a False: no run is cut
    order = (start + np.arange(n)) % n
    runs, current = [], []
    for i in order:
        if mask[i]:
            current.append(i)
        elif current:
            runs.append(np.array(current))
            current = []
    if current:
        runs.append(np.array(current))
    return runs


def segment_landmarks(panorama: np.ndarray, config: ALVConfig = ALVConfig()) -> Landmarks:
    """The landmarks of a panorama: runs of the thresholded horizon ring (module doc)."""
    ring = signature_from_panorama(panorama, config.n_samples, config.rows).astype(np.float64)
    theta = bearing_grid(config.n_samples)
    threshold = otsu_threshold(ring)
    if float(ring.max() - ring.min()) < config.min_contrast:
        empty = np.zeros(0)
        return Landmarks(empty, empty, threshold, ring)
    masks = {"dark": [ring < threshold], "bright": [ring >= threshold],
             "both": [ring < threshold, ring >= threshold]}[config.polarity]
    step = 2 * np.pi / config.n_samples
    bearings, widths = [], []
    for mask in masks:
        for run in circular_runs(mask):
            width = run.size * step
            if width < math.radians(config.min_width) or run.size == config.n_samples:
                continue
            c, s = np.cos(theta[run]).sum(), np.sin(theta[run]).sum()
            bearings.append(math.atan2(s, c))
            widths.append(width)
    return Landmarks(np.array(bearings), np.array(widths), threshold, ring)


def average_landmark_vector(bearings: np.ndarray) -> np.ndarray:
    """ALV: the mean of the unit vectors at ``bearings`` (radians); zero if none."""
    b = np.asarray(bearings, np.float64)
    if b.size == 0:
        return np.zeros(2)
    return np.array([np.cos(b).mean(), np.sin(b).mean()])


def alv_home_vector(current: np.ndarray, home_alv: np.ndarray, psi: float,
                    config: ALVConfig = ALVConfig()) -> tuple[np.ndarray, Landmarks]:
    """Home vector ``ALV(current) - ALV(home)`` in the home frame, the current view's
    landmarks rotated by the compass angle ``psi`` (robot heading relative to the home
    heading, radians)."""
    marks = segment_landmarks(current, config)
    return average_landmark_vector(marks.bearings + psi) - np.asarray(home_alv), marks


@dataclass
class ALVController(Controller):
    """Lambrinos et al. 2000 ALV homing with the RIDF visual compass (module doc).

    ``step_length`` metres per move; stops when the home vector is shorter than
    ``stop_length``, when no landmark is seen, or after ``max_steps`` moves;
    ``compass_levels``: pyramid reductions of the images the compass compares. The
    segmentation fields are :class:`ALVConfig`'s."""

    step_length: float = 0.1
    stop_length: float = 0.06
    max_steps: int = 60
    compass_levels: int = 2
    n_samples: int = ALVConfig.n_samples
    rows: int = ALVConfig.rows
    polarity: str = ALVConfig.polarity
    min_width: float = ALVConfig.min_width
    min_contrast: float = ALVConfig.min_contrast

    def validate(self) -> None:
        require_positive("alv: step_length", self.step_length, "metres")
        require_number("alv: stop_length", self.stop_length, 0, 2)
        require_number("alv: max_steps", self.max_steps, 1, 100_000, integer=True)
        require_number("alv: compass_levels", self.compass_levels, 0, 5,
                       "pyramid reductions", integer=True)
        self.config = ALVConfig(n_samples=self.n_samples, rows=self.rows,
                                polarity=self.polarity, min_width=self.min_width,
                                min_contrast=self.min_contrast)

    def observation_keys(self) -> tuple[str, ...]:
        return ("panorama", "goal", "odometry")

    def on_reset(self) -> None:
        self._offset: float | None = None
        self._best_ratio = math.inf
        self._steps = 0
        self._stopped = False
        self.last_vector: np.ndarray | None = None
        self.last_compass: float | None = None

    def decide(self, observation) -> Move | None:
        goal = observation["goal"]
        if self.is_new_goal(goal):              # a new target: store its ALV
            self._goal_grey = grey_panorama(goal, self.compass_levels)
            self._home_alv = average_landmark_vector(
                segment_landmarks(goal, self.config).bearings)
            self._steps, self._stopped = 0, False
            self._offset, self._best_ratio = None, math.inf
        if self._stopped or self._steps >= self.max_steps:
            return None
        current = observation["panorama"]
        psi, d, median = visual_compass(grey_panorama(current, self.compass_levels),
                                        self._goal_grey)
        if "odometry" in observation:
            yaw = float(observation["odometry"][2])
            ratio = d / median if median > 0 else 0.0
            if ratio < self._best_ratio:       # the best-matching view so far re-anchors
                self._best_ratio, self._offset = ratio, wrap_angle(psi - yaw)
            psi = wrap_angle(yaw + self._offset)
        vector, marks = alv_home_vector(current, self._home_alv, psi, self.config)
        self.last_vector, self.last_compass = vector, psi
        if marks.bearings.size == 0 or float(np.hypot(*vector)) < self.stop_length:
            self._stopped = True
            return None
        self._steps += 1
        return Move(wrap_angle(math.atan2(vector[1], vector[0]) - psi), self.step_length)
