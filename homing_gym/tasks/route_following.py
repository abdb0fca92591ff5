"""Route following: visit a sequence of target places, each known by its snapshot
(Hong et al. 1991 §5: 17 targets about 1 ft apart in a hallway, the robot starting 1 ft
before the first), or the targets of a route given as points (curved routes).

Teaching views (opt-in, observation key ``route_views``): the panoramas the robot took
while it was led along the route, for methods that learn a route from the views along it
(familiarity-based route following, Baddeley et al. 2012). They are taken at
:func:`route_view_poses`, each facing the direction of travel there, under snapshot-time
lighting (as the targets' snapshots), at reset whenever the route or the world is new (a
fixed route in a world that does not change keeps its views), and reach the agent through
the observation, never through ``info``.

Random routes (``route="random"``): each episode draws its own curved route of
``n_targets`` legs of ``spacing`` metres, turning by up to :data:`RANDOM_ROUTE_TURN` per
leg, through the free floor of the episode's world (:func:`~homing_gym.tasks.base.
random_route`): routes through any world, built-in, procedural or a user's mesh.
"""

from __future__ import annotations

import math
import numbers
import os
import reprlib
from collections.abc import Sequence

import numpy as np

from gymnasium import spaces

from homing_gym.geometry import FOOT, wrap_angle
from homing_gym.observations import ObservationKey
from homing_gym.paths import BODY_RADIUS, joined_in_order
from homing_gym.scenes.base import MAX_SIDE, Scene, clearances
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import (Episode, check_start_jitter, check_start_off_goal,
                                   checked_start_jitter, random_route, sample_free_pose)
from homing_gym.tasks.goal_reaching import GoalReachingTask, RewardConfig
from homing_gym.tasks.route_file import MAX_ROUTE_POINTS, load_route
from homing_gym.validation import require_number

#: The straight route's defaults: Hong et al.'s 17 targets 1 ft apart.
N_TARGETS, SPACING = 17, FOOT
#: Least distance (metres) between consecutive points of a given route.
MIN_ROUTE_STEP = 0.05
#: Default, least and largest distance (metres) between the route's teaching views.
ROUTE_VIEW_SPACING, MIN_ROUTE_VIEW_SPACING, MAX_ROUTE_VIEW_SPACING = 0.1, 0.01, 2.0
#: Most teaching views one route may have (each a full panorama in every observation).
MAX_ROUTE_VIEWS = 512
#: The observation key of the teaching views.
ROUTE_VIEWS_KEY = "route_views"
#: ``route`` asking for a random route per episode (a route file of that name: "./random").
RANDOM_ROUTE = "random"
#: Largest turn (radians) between consecutive legs of a random route: 30 degrees per leg
#: bends a route of 17 one-foot legs by about 70 degrees on average (Baddeley et al.'s
#: routes meander without looping back); any direction for the first leg.
RANDOM_ROUTE_TURN = math.radians(30)


def _is_sequence(value) -> bool:
    """A list, tuple or array of at least one dimension (not a string)."""
    return ((isinstance(value, Sequence) and not isinstance(value, str))
            or (isinstance(value, np.ndarray) and value.ndim >= 1))


def _route_point(k: int, point) -> tuple[float, ...]:
    """Point ``k`` of a route as 2 or 3 floats; ``ValueError`` unless it is (x, y) or
    (x, y, yaw) of finite real numbers."""
    ok = (_is_sequence(point) and len(point) in (2, 3)
          and all(isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v)
                  for v in point))
    if not ok:
        raise ValueError(f"route point {k} must be (x, y) or (x, y, yaw): 2 or 3 finite "
                         f"numbers (metres, radians), got {point!r}")
    return tuple(float(v) for v in point)


def route_poses(route: Sequence[Sequence[float]]) -> np.ndarray:
    """The poses ``(N, 3)`` (x, y, yaw; metres, radians counter-clockwise from +x) of a
    route given as ``N >= 2`` points (x, y) or (x, y, yaw). A missing yaw is the direction
    of travel from the previous point (for the first point: towards the second).
    ``ValueError`` for fewer than two points, a bad point, or consecutive points less than
    ``MIN_ROUTE_STEP`` metres apart."""
    if not _is_sequence(route) or len(route) < 2:
        raise ValueError(f"route must be a sequence of at least two points (x, y) or "
                         f"(x, y, yaw), got {reprlib.repr(route)}")
    if len(route) > MAX_ROUTE_POINTS:
        raise ValueError(f"route holds {len(route)} points; at most {MAX_ROUTE_POINTS} "
                         f"(the start and the targets), as a route file")
    points = [_route_point(k, p) for k, p in enumerate(route)]
    xy = np.array([p[:2] for p in points])
    dx, dy = np.diff(xy, axis=0).T
    steps = np.hypot(dx, dy)
    for k in np.flatnonzero(steps < MIN_ROUTE_STEP)[:1] + 1:
        raise ValueError(f"route points {k - 1} {points[k - 1]} and {k} {points[k]} are "
                         f"{steps[k - 1]:.3f} m apart; consecutive points must be at least "
                         f"{MIN_ROUTE_STEP} m apart")
    travel = np.arctan2(dy, dx)
    travel = np.concatenate([travel[:1], travel])
    yaws = [wrap_angle(p[2]) if len(p) == 3 else a for p, a in zip(points, travel)]
    return np.column_stack([xy, yaws])


def route_view_poses(points, spacing: float) -> np.ndarray:
    """The poses ``(K, 3)`` (x, y, yaw) of the teaching views along the polyline
    ``points`` (``(N, 2+)``, metres: the start point, then the targets): ``K =
    ceil(L / spacing) + 1`` places evenly spread over its length ``L``, the first at the
    start, the last at the last target, consecutive places at most ``spacing`` apart along
    the route; each faces the direction of travel there (the leg that leaves it; at the
    last target, the last leg's). ``ValueError`` naming ``route_view_spacing`` when the
    route is shorter than ``spacing`` (fewer than two views: nothing to follow) or needs
    more than :data:`MAX_ROUTE_VIEWS` views."""
    xy = np.asarray(points, np.float64)[:, :2]
    legs = np.diff(xy, axis=0)
    lengths = np.hypot(legs[:, 0], legs[:, 1])
    total = float(lengths.sum())
    if total < spacing:
        raise ValueError(f"route_view_spacing {spacing!r} m: the route is only {total:.3f} m "
                         f"long, too short for teaching views (at least two, "
                         f"route_view_spacing apart); give a route_view_spacing of at most "
                         f"{total:.3f} m or a longer route")
    count = int(math.ceil(total / spacing - 1e-9)) + 1
    if count > MAX_ROUTE_VIEWS:
        raise ValueError(f"route_view_spacing {spacing!r} m: the route of {total:.2f} m needs "
                         f"{count} teaching views, at most {MAX_ROUTE_VIEWS}; use a "
                         f"route_view_spacing of at least "
                         f"{math.ceil(total / (MAX_ROUTE_VIEWS - 1) * 1000) / 1000:.3f} m")
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    stations = np.linspace(0.0, total, count)
    leg = np.clip(np.searchsorted(cum, stations, side="right") - 1, 0, len(legs) - 1)
    while np.any(lengths[leg] == 0):          # (consecutive points are apart: never)
        leg = np.minimum(leg + (lengths[leg] == 0), len(legs) - 1)
    along = np.clip((stations - cum[leg]) / lengths[leg], 0.0, 1.0)
    places = xy[leg] + legs[leg] * along[:, None]
    places[-1] = xy[-1]
    return np.column_stack([places, np.arctan2(legs[leg, 1], legs[leg, 0])])


class RouteFollowingTask(GoalReachingTask):
    """By default ``n_targets`` target poses ``spacing`` metres apart on a straight line
    from the scene's ``metadata["route_origin"]`` (x, y, yaw), all facing along the route,
    the robot starting ``spacing`` metres before the first target. With ``route`` (points
    (x, y) or (x, y, yaw), see :func:`route_poses`) the robot starts at its first point and
    the other points are the targets, in order; ``n_targets`` and ``spacing`` must then
    keep their defaults. With ``route="random"`` each episode draws a curved route of
    ``n_targets`` legs of ``spacing`` metres (see the module doc), every point and leg
    ``clearance_margin`` metres clear, its start clear of the jitter too. The start is perturbed by up to ``start_jitter = (metres,
    radians)`` (uniform in x, y and yaw). Every point of the straight route needs
    ``clearance_margin`` metres of clearance, every point of a given route room for the
    robot's body; each point must be joined to the next by a path for a disc of that
    radius (:meth:`check_scene`). A target counts as reached within ``success_radius``
    (default 0.1 m, a third of the spacing), or, with ``success_on="stop"``, when the
    agent stops; then the next target's snapshot becomes the goal.

    Teaching views (observation key :data:`ROUTE_VIEWS_KEY`, when asked for): the
    panoramas at :func:`route_view_poses` of the route (start point and targets as
    taught, before the start's jitter), at most ``route_view_spacing`` metres apart."""

    def __init__(self, n_targets: int = N_TARGETS, spacing: float = SPACING,
                 start_jitter: tuple[float, float] = (0.05, math.radians(10)),
                 success_radius: float = 0.1, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig(), clearance_margin: float = 0.18,
                 route: Sequence[Sequence[float]] | str | os.PathLike | None = None,
                 route_view_spacing: float = ROUTE_VIEW_SPACING):
        self.random_route = isinstance(route, str) and route == RANDOM_ROUTE
        route = None if self.random_route else load_route(route)   # a path: its points
        require_number("n_targets", n_targets, 1, MAX_ROUTE_POINTS - 1, "(a route holds at "
                       f"most {MAX_ROUTE_POINTS} points with its start)", integer=True)
        require_number("spacing", spacing, MIN_ROUTE_STEP, MAX_SIDE, "metres (the least "
                       "step of a route; the largest side of a scene)")
        require_number("route_view_spacing", route_view_spacing, MIN_ROUTE_VIEW_SPACING,
                       MAX_ROUTE_VIEW_SPACING, "metres (between the route's teaching views)")
        start_jitter = checked_start_jitter(start_jitter)
        if route is not None and (n_targets != N_TARGETS or spacing != SPACING):
            raise ValueError(f"n_targets ({n_targets!r}) and spacing ({spacing!r}) describe the "
                             f"straight route; with a route given they must keep their "
                             f"defaults ({N_TARGETS}, {SPACING}): the route's points set both")
        super().__init__(success_radius, success_on, reward)
        self.route = None if route is None else route_poses(route)
        self.n_targets = int(n_targets) if route is None else len(self.route) - 1
        self.spacing = float(spacing)
        self.start_jitter = start_jitter
        self.clearance_margin = clearance_margin
        self.route_view_spacing = float(route_view_spacing)
        self._views: np.ndarray | None = None
        self._views_of: tuple | None = None           # (scene, route) the views show
        self._drawn: np.ndarray | None = None         # this episode's random route

    def _route(self, scene: Scene) -> np.ndarray:
        """The start point, then the targets: poses ``(n_targets + 1, 3)`` (a random
        route: this episode's)."""
        if self.random_route:
            return self._drawn.copy()
        if self.route is not None:
            return self.route.copy()
        x0, y0, yaw = scene.metadata["route_origin"]
        k = np.arange(-1, self.n_targets)
        return np.column_stack([x0 + k * self.spacing * math.cos(yaw),
                                y0 + k * self.spacing * math.sin(yaw), np.full(len(k), yaw)])

    @property
    def path_radius(self) -> float:
        """A given route needs room for the robot's body only (:data:`BODY_RADIUS`
        metres); the straight route ``clearance_margin``."""
        return BODY_RADIUS if self.route is not None else self.clearance_margin

    def check_scene(self, scene: Scene) -> None:
        """``ValueError`` unless every point of the route is clear (:attr:`path_radius`
        metres) and each is joined to the next by a path for a disc of that radius
        (:func:`homing_gym.paths.connected`), and every start of the jitter is clear."""
        if self.random_route:
            check_start_off_goal((0.0, 0.0), (self.spacing, 0.0), self.success_radius,
                                 "a random route's start and its first target")
            return
        if self.route is None and "route_origin" not in scene.metadata:
            raise ValueError(f"scene {scene.name!r} defines no route (metadata['route_origin']); "
                             f"use a scene with one, e.g. 'hallway', or give route=[...]")
        if self.route is None:
            self._check_straight_fit(scene)
        points, radius = self._route(scene), self.path_radius
        free = np.maximum(clearances(scene, points[:, :2]), 0.0)   # all points at once
        if self.route is not None:
            self._check_route_points(scene, points, free)
        for k in np.flatnonzero(free < radius)[:1]:
            raise ValueError(
                f"{self.n_targets} targets {self.spacing} m apart do not fit along "
                f"the route of scene {scene.name!r}: ({points[k, 0]:.2f}, "
                f"{points[k, 1]:.2f}) is blocked")
        for k in np.flatnonzero(~joined_in_order(scene, points, radius))[:1] + 1:
            a, b = points[k - 1], points[k]
            raise ValueError(f"route points {k - 1} ({a[0]:.3f}, {a[1]:.3f}) and {k} "
                             f"({b[0]:.3f}, {b[1]:.3f}) are not joined by any path for a "
                             f"disc of {radius} m radius in scene {scene.name!r}")
        check_start_jitter(scene, points[0], self.start_jitter[0], radius, "the route's start")
        check_start_off_goal(points[0], points[1], self.success_radius,
                             "the route's start and its first target")

    def _check_straight_fit(self, scene: Scene) -> None:
        """``ValueError`` if the last target of the straight route would lie outside the
        scene's bounds less ``path_radius`` (arithmetic: nothing built), saying how many
        targets fit."""
        (xmin, ymin), (xmax, ymax) = scene.bounds
        x0, y0, yaw = scene.metadata["route_origin"]
        step = self.spacing * np.array([math.cos(yaw), math.sin(yaw)])
        low = np.array([xmin, ymin]) + self.path_radius
        high = np.array([xmax, ymax]) - self.path_radius
        last = np.array([x0, y0]) + (self.n_targets - 1) * step
        if np.all((low <= last) & (last <= high)):
            return
        with np.errstate(divide="ignore", invalid="ignore"):   # steps along one axis
            room = np.where(step > 0, (high - (x0, y0)) / step,
                            np.where(step < 0, (low - (x0, y0)) / step, np.inf))
        fits = max(int(math.floor(float(np.min(room)))) + 1, 0)
        raise ValueError(f"{self.n_targets} targets {self.spacing} m apart do not fit along "
                         f"the route of scene {scene.name!r}: the last would be at "
                         f"({last[0]:.2f}, {last[1]:.2f}), outside its bounds {scene.bounds} "
                         f"less {self.path_radius} m; at most {fits} fit")

    @staticmethod
    def _check_route_points(scene: Scene, points: np.ndarray, free: np.ndarray) -> None:
        """``ValueError`` naming the first point of the given route that lies outside
        ``scene.bounds`` or closer than the robot's body radius to a wall or object (by
        how much); ``free`` holds the points' clearances."""
        (xmin, ymin), (xmax, ymax) = scene.bounds
        x, y = points[:, 0], points[:, 1]
        outside = np.flatnonzero((x < xmin) | (x > xmax) | (y < ymin) | (y > ymax))
        tight = np.flatnonzero(free < BODY_RADIUS)
        for k in sorted([*outside[:1], *tight[:1]])[:1]:
            where = f"route point {k} ({x[k]:.3f}, {y[k]:.3f})"
            if k in outside:
                raise ValueError(f"{where} lies outside the bounds of scene {scene.name!r}: "
                                 f"x in [{xmin}, {xmax}], y in [{ymin}, {ymax}] m")
            raise ValueError(f"{where} is {free[k]:.3f} m from the nearest wall or object in "
                             f"scene {scene.name!r}; the robot's body needs {BODY_RADIUS:.3f} "
                             f"m ({BODY_RADIUS - free[k]:.3f} m short)")

    def _random_route(self, scene: Scene, rng: np.random.Generator) -> np.ndarray:
        """A random route's poses (start point, then targets): a start drawn clear of the
        jitter (:func:`sample_free_pose`), then up to 25 tries of :func:`random_route` at
        ``clearance_margin`` from it (a start in a small room may have no room for the
        route), kept once the grid the oracle plans on joins its points in order; up to
        40 starts, then ``ValueError`` naming the scene and the route."""
        margin, jitter = self.clearance_margin, self.start_jitter[0]
        for _ in range(40):
            start = sample_free_pose(scene, rng, margin + jitter * math.sqrt(2))
            try:
                points = random_route(scene, start, rng, self.n_targets * self.spacing, margin,
                                      legs=(self.spacing, self.spacing),
                                      max_turn=RANDOM_ROUTE_TURN, max_restarts=25)
            except ValueError:
                continue
            if joined_in_order(scene, points, margin).all():
                return route_poses(points)
        raise ValueError(f"scene {scene.name!r} of size {scene.size} m holds no random route "
                         f"of {self.n_targets} legs of {self.spacing} m turning by up to "
                         f"{math.degrees(RANDOM_ROUTE_TURN):.0f} deg with {margin} m of "
                         f"clearance (40 starts tried); use fewer targets, a shorter spacing "
                         f"or a more open scene")

    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        if self.random_route:
            self._drawn = self._random_route(scene, rng)
        before, *targets = self._route(scene)
        d, a = self.start_jitter
        start = before + np.array([rng.uniform(-d, d), rng.uniform(-d, d), rng.uniform(-a, a)])
        start[2] = wrap_angle(start[2])
        return Episode(home=targets[-1], start=start, waypoints=tuple(targets[:-1]))

    # -- teaching views -----------------------------------------------------------------------
    def _view_count(self) -> int:
        """How many teaching views the route has (:func:`route_view_poses`; its length does
        not depend on the scene); ``ValueError`` naming ``route_view_spacing`` when the
        route is too short for them or needs too many."""
        if self.route is not None:
            points = self.route
        else:        # straight or random: n_targets spacings from the start point
            points = np.array([[0.0, 0.0], [self.n_targets * self.spacing, 0.0]])
        return len(route_view_poses(points, self.route_view_spacing))

    def on_reset(self, ctx: TaskContext) -> None:
        route = None if self._drawn is None else self._drawn.tobytes()
        shown = self._views_of is not None and (self._views_of[0] is ctx.scene()
                                                and self._views_of[1] == route)
        if ROUTE_VIEWS_KEY in ctx.obs_keys and not shown:
            poses = route_view_poses(self._route(ctx.scene()), self.route_view_spacing)
            self._views = np.stack([ctx.snapshot(pose) for pose in poses])
            self._views_of = (ctx.scene(), route)
            ctx.place_robot(ctx.episode().start, self.fresh_contacts)
        super().on_reset(ctx)

    def observation_keys(self) -> dict[str, ObservationKey]:
        def space(config):
            count = self._view_count()
            return spaces.Box(0, 255, (count, *config.panorama_shape, 3), np.uint8)

        return {ROUTE_VIEWS_KEY: ObservationKey(space, lambda sight: self._views.copy(),
                                                rendered=False)}

    def extra_info(self, ctx: TaskContext) -> dict:
        return {"target_index": ctx.goal_index(), "target_errors": list(self.goal_errors)}
