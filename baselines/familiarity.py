"""Familiarity-based route following, Baddeley, Graham, Husbands & Philippides (2012).

"A model of ant route navigation driven by scene familiarity", PLoS Comput Biol 8(1):
e1002336. An ant that walks a route faces the way it travels, so a view it learnt there
also says which way to go: "route navigation can be re-cast as a search for familiar
views", performed "with a simple scanning routine" (abstract). At each step the agent
*scans* (turns through a range of headings, comparing the view at each with its memory
of the route's views), then moves a step in the direction whose view is the most
familiar. Familiarity comes from one of two memories:

* **Perfect Memory**: the training views themselves; the familiarity of a view is given
  by its smallest image difference to any of them ("exhaustive comparison with the set
  of views experienced during training", abstract)
  (:class:`homing_baselines.perfect_memory.PerfectMemory`).
* **Infomax**: a two-layer network trained once on the route's views, each presented
  once in travel order, with the Infomax rule of Bell & Sejnowski (1995) in the form
  Lulham, Bogacz, Vogt & Brown (2011, Neural Computation 23: "An infomax algorithm can
  perform both familiarity discrimination and feature extraction in a single network")
  use for familiarity discrimination: ``h = W x``, ``y = tanh(h)``,
  ``dW = eta / N (W - (y + h) h^T W)`` (``N`` inputs; the authors' training code,
  ``infomax_learn2``, writes it ``W += lrate/N * (I - (y+u) u') * W`` with ``u = W x``),
  and the *novelty* of a view is the summed absolute activation ``sum_i |h_i|`` of the
  output layer; the most familiar heading has the least novelty
  (:class:`homing_baselines.infomax.InfomaxNetwork`).

The scan (:func:`scan_views`): the current panorama rotated by whole column shifts, which
is the view the robot would see after turning on the spot by that angle (a physical scan
gives the same views, up to the body's turning, at the cost of the turns; the virtual scan
is the usual simulation shortcut). A left turn by ``psi`` moves the content
``psi W / (2 pi)`` columns to the right (column ``x`` has bearing ``pi - 2 pi x / W``).

Our choices where the paper leaves the setting to the simulation (each with its reason):

* **Image**: the panorama's luminance reduced ``levels`` = 1 time by the seamless
  Gaussian pyramid (48 x 256 -> 24 x 128, 2.8 deg per column). The paper's images are low
  resolution too (the authors' code takes 17 x 90 = 1530 pixels, 4 deg per column);
  low-pass filtering widens the catchment of a view (Stürzl & Zeil 2007) and makes the
  memory small. ``levels`` was chosen on validation draws of the ``routes`` settings
  (seeds 100,000 past the canonical ones, 30 routes each): at 2 reductions (12 x 64,
  5.6 deg) the robot drifted off the natural routes among trees (Perfect Memory's last
  stop within the radius 70 % -> 93 % at 1, rooms 77 % -> 83 %; Infomax natural 63 % ->
  97 %), at 3 it lost them (23 %). Each image is normalised to zero mean and unit
  variance before it is compared or learnt, so that a change of overall brightness is
  not a change of place (our worlds' snapshots and runs share one lighting unless
  ``lighting_change`` is set).
* **Image difference** (Perfect Memory): the root-mean-square pixel difference (Zeil,
  Hofmann & Chahl 2003's IDF, the measure of :mod:`homing_baselines.did`), for all views
  and all scanned rotations at once. The paper's text does not fix the measure here.
* **Scan**: headings within ``scan_width_deg`` / 2 of the current heading, every
  ``scan_step`` columns. Default 180 deg (+-90 deg): a route follower faces roughly along
  the route, and the back half of a corridor's panorama resembles the front half
  mirrored, so a full 360 deg scan lets the agent turn back onto the route it came
  along; the range of the scan is a parameter (``scan_width_deg`` = 360 allowed).
* **Step**: ``step_length`` = 0.05 m per decision in the most familiar direction, the
  heading refined between columns by the parabola through the best scanned shift and
  its neighbours (:func:`best_shift`; a whole column, 2.8 deg, lets the robot drift
  sideways along a corridor). Short steps keep the overshoot of the stop small (below);
  0.1 m steps followed the hallway as well but stopped 0.07-0.1 m past each target.
* **Learning** (Infomax): ``W`` starts from a seeded standard normal matrix with each
  row scaled to unit standard deviation (as the authors' ``infomax_init2``), ``N`` hidden
  units for ``N`` inputs (as the paper's network), one pass over the views in travel
  order (the paper: each view learnt once, as the ant walks the route), learning rate
  ``learning_rate``.

**Stopping and the targets** (:meth:`FamiliarityController.stop_now`). The paper's
agents walk a route and are judged on how far along it they stay; they have no stop and
no targets. RouteFollowing-v0 under its protocols' rule (``success_on="stop"``) wants a
stop at every target, and the env then makes the next target's snapshot the ``goal``.
The familiarity memory steers; the stop reads the target's snapshot, the same way for
both memories: the rotation-invariant RMS difference ``d`` between the current view and
the ``goal`` (the RIDF minimum of :func:`homing_baselines.did.visual_compass`) falls as the
robot nears the target along the route and rises once it has passed it. Per target, with
``d_0`` the difference at the target's first decision, the robot stops

* when ``d`` rises above ``(1 + rise)`` times the least so far (it has passed the target,
  by at most one step), or
* when the fall of ``d`` levels off (the last fall below ``flatten`` times the one before:
  the minimum is within about a step),

either only once the least ``d`` so far is below ``near * d_0`` (the target is near:
far from it the difference of two views is flat and noisy, and a rise there means
nothing); and after ``max_target_steps`` decisions for one target (a safety limit).
``near`` = 0.8 was chosen on a validation draw of the ``routes`` protocol (``homing-eval
--protocol routes --seed 100000``: none of the canonical draw's episodes): at 0.6 the
difference to a target 0.3 m ahead among trees and rocks often never fell below 0.6
``d_0``, the robot drove past it without stopping, and the goal was then a target left
behind (with 2 pyramid reductions, Perfect Memory's last stop within the radius on 2 of
10 natural routes; 8 of 10 at 0.8 and at 0.9, which stopped short of more targets on
the way: every target in 5 and 1 of 10; Infomax 2 of 10 -> 6 of 10 at 0.8). With 1
reduction (the default) 0.7, 0.8 and 0.9 did alike on 30 validation natural routes
(Perfect Memory 28, 28 and 29 of 30), so 0.8 stayed.
A stop leaves the target (the env's rule, whatever the distance); the scan then
continues along the route towards the next target. The stop reads only the ``goal``
observation, which every method of the route protocol gets. Why not a stop from the
route memory (the best-matching training view being the last one): Infomax keeps no
views, so it could not use it, and the targets lie between the training views. Why not
step back to the minimum after passing it: the robot's motors ramp (2 m/s^2), so a short
backward move right after a forward one travels a fraction of its length (measured:
0.03 m of 0.11 m in the hallway); short steps (``step_length`` = 0.05 m) bound the
overshoot instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.did import grey_panorama, visual_compass
from homing_baselines.motion import Move
from homing_gym.geometry import wrap_angle
from homing_gym.tasks.route_following import ROUTE_VIEWS_KEY
from homing_gym.validation import require_number


def normalised(images: np.ndarray) -> np.ndarray:
    """Each image of ``images`` (``(..., h, w)``) flattened and scaled to zero mean and unit
    variance (a flat image stays zero): ``(..., h * w)`` float64."""
    flat = np.asarray(images, np.float64).reshape(*np.shape(images)[:-2], -1)
    flat = flat - flat.mean(axis=-1, keepdims=True)
    sd = flat.std(axis=-1, keepdims=True)
    return flat / np.where(sd > 0, sd, 1.0)


def scan_shifts(width: int, scan_width_deg: float, scan_step: int = 1) -> np.ndarray:
    """The column shifts of a scan over ``scan_width_deg`` (centred on the current heading,
    0 included) of panoramas ``width`` columns wide, every ``scan_step`` columns; a
    360-degree scan has each shift once."""
    half = int(math.floor(scan_width_deg / 360.0 * width / 2 + 1e-9))
    half = min(half, width // 2)
    shifts = np.arange(-half, half + 1, scan_step)
    shifts = np.union1d(shifts, [0])
    return np.unique(((shifts + width // 2) % width) - width // 2)


def scan_views(image: np.ndarray, shifts: np.ndarray) -> np.ndarray:
    """``(S, h, w)``: the grey ``image`` ``(h, w)`` as seen after turning on the spot by
    each shift (``np.roll`` by ``+k`` columns = a left turn by ``2 pi k / w``)."""
    return np.stack([np.roll(image, int(k), axis=1) for k in shifts])


def shift_angle(shift: float, width: int) -> float:
    """The turn (radians, counter-clockwise) of a scan shift of ``shift`` columns."""
    return wrap_angle(2 * math.pi * shift / width)


def best_shift(shifts: np.ndarray, scores: np.ndarray) -> float:
    """The shift (columns, fractional) of the least score: the best scanned shift refined
    by the parabola through it and its two neighbours (when both were scanned one column
    away), at most half a column either way."""
    k = int(np.argmin(scores))
    best = float(shifts[k])
    if 0 < k < len(shifts) - 1 and shifts[k + 1] - shifts[k] == 1 == shifts[k] - shifts[k - 1]:
        a, b, c = scores[k - 1], scores[k], scores[k + 1]
        curve = a - 2 * b + c
        if curve > 0:
            best += float(np.clip(0.5 * (a - c) / curve, -0.5, 0.5))
    return best


@dataclass
class FamiliarityController(Controller):
    """Scan, then step towards the most familiar heading (see the module doc); the memory
    is made by :meth:`make_memory` from the route's views (``route_views``) at the first
    decision of an episode (again if the views change: a new world). Lengths in metres.

    ``step_length``: each move; ``scan_width_deg``: the range of headings scanned
    (degrees, centred on the heading); ``scan_step``: columns between scanned headings;
    ``levels``: pyramid reductions of the panoramas; ``rise``, ``flatten``, ``near``,
    ``max_target_steps``: the stop rule (:meth:`stop_now`). Subclasses give the memory
    (:meth:`make_memory`)."""

    reads_at_decisions_only: ClassVar[bool] = True
    envs: ClassVar[tuple[str, ...] | None] = ("homing_gym/RouteFollowing-v0",)

    step_length: float = 0.05
    scan_width_deg: float = 180.0
    scan_step: int = 1
    levels: int = 1
    rise: float = 0.02
    flatten: float = 0.5
    near: float = 0.8
    max_target_steps: int = 60

    def validate(self) -> None:
        who = self.name or type(self).__name__
        require_number(f"{who}: step_length", self.step_length, 0, 2, "metres",
                       low_open=True)
        require_number(f"{who}: scan_width_deg", self.scan_width_deg, 0, 360, "degrees",
                       low_open=True)
        require_number(f"{who}: scan_step", self.scan_step, 1, 64, "columns", integer=True)
        require_number(f"{who}: levels", self.levels, 0, 5, "pyramid reductions",
                       integer=True)
        require_number(f"{who}: rise", self.rise, 0, 1)
        require_number(f"{who}: flatten", self.flatten, 0, 1)
        require_number(f"{who}: near", self.near, 0, 1)
        require_number(f"{who}: max_target_steps", self.max_target_steps, 1, 100_000,
                       integer=True)

    def observation_keys(self) -> tuple[str, ...]:
        return ("panorama", "goal", ROUTE_VIEWS_KEY)

    def make_memory(self, views: np.ndarray):
        """The familiarity memory of the grey training views ``(K, h, w)``: an object with
        ``unfamiliarity(images (S, h, w)) -> (S,)``."""
        raise NotImplementedError

    def on_reset(self) -> None:
        self._views: np.ndarray | None = None
        self.memory = None
        self.last_scan: np.ndarray | None = None
        self.last_goal_difference: float | None = None
        self._new_target()

    def _new_target(self) -> None:
        self._goal_grey: np.ndarray | None = None
        self._differences: list[float] = []
        self._stopped = False

    def learn_route(self, views: np.ndarray) -> None:
        """Make the memory of the route's views ``(K, H, W, 3)`` (kept while the same
        views come again)."""
        if self._views is not None and np.array_equal(views, self._views):
            return
        if views.ndim != 4 or len(views) < 2:
            raise ValueError(f"{self.name}: observation {ROUTE_VIEWS_KEY!r} must hold at "
                             f"least two panoramas (K, H, W, 3), got shape {views.shape}")
        self._views = np.array(views, copy=True)
        self.memory = self.make_memory(np.stack([grey_panorama(v, self.levels)
                                                 for v in views]))

    def decide(self, observation) -> Move | None:
        if ROUTE_VIEWS_KEY not in observation:
            raise ValueError(f"{self.name}: needs the observation key {ROUTE_VIEWS_KEY!r} "
                             f"(RouteFollowing-v0 with obs_keys including it)")
        self.learn_route(np.asarray(observation[ROUTE_VIEWS_KEY]))
        goal = observation["goal"]
        if self.is_new_goal(goal):              # the route's next target
            self._new_target()
            self._goal_grey = grey_panorama(goal, self.levels)
        if self._stopped:
            return None
        now = grey_panorama(observation["panorama"], self.levels)
        _, difference, _ = visual_compass(now, self._goal_grey)
        self.last_goal_difference = difference
        if self.stop_now(difference):
            self._stopped = True
            return None
        shifts = scan_shifts(now.shape[1], self.scan_width_deg, self.scan_step)
        scores = self.memory.unfamiliarity(scan_views(now, shifts))
        self.last_scan = np.column_stack([shifts, scores])
        return Move(shift_angle(best_shift(shifts, scores), now.shape[1]), self.step_length)

    def stop_now(self, difference: float) -> bool:
        """Whether to stop at the current target now, ``difference`` the current view's
        rotation-invariant RMS difference to the target's snapshot (the rule: module
        doc, "Stopping and the targets")."""
        history = self._differences
        best = min(history, default=math.inf)
        history.append(difference)
        if len(history) > self.max_target_steps:
            return True
        if best > self.near * history[0]:
            return False                    # not yet near: far views differ at random
        if difference > best * (1 + self.rise):
            return True                     # past the target: the difference rises again
        if len(history) < 3 or difference > self.near * history[0]:
            return False
        last, before = history[-2] - history[-1], history[-3] - history[-2]
        return before > 0 and last < self.flatten * before      # the fall levels off
