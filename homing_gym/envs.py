"""The registered environments. Each class docstring is the env card shown in ``docs/``."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from homing_gym.env import HomingEnv, check_env_kwargs
from homing_gym.geometry import FOOT
from homing_gym.render.panorama import CameraConfig
from homing_gym.scenes import SceneFactory, scene_factory
from homing_gym.scenes.base import Scene
from homing_gym.scenes.daily_changes import daily_changes as daily_changes_of
from homing_gym.scenes.landmark_changes import changed_landmarks
from homing_gym.tasks import (LocalHomingTask, LongRangeHomingTask, RewardConfig,
                              RouteFollowingTask)
from homing_gym.tasks.landmark_navigation import LandmarkNavigationTask
from homing_gym.tasks.route_following import ROUTE_VIEW_SPACING
from homing_gym.tasks.work_locations import MAX_POINTS, TAUGHT_KEYS, WorkLocationsTask
from homing_gym.teaching import PLACE_SPACING
from homing_gym.tasks.goal_reaching import MAX_SUCCESS_RADIUS
from homing_gym.validation import require_number, require_sequence

#: A row of an env card's argument table for a task's own argument: (allowed values,
#: unit, meaning); the default is the env class's (:mod:`homing_gym.envcard`).
Row = tuple[str, str, str]
SCENE: Row = ("a registered scene name, `'mesh:PATH'` (a mesh file) or a `Scene`", "",
              "the world")
SUCCESS_ON: Row = ("`'stop'`, `'reach'`", "",
                   "`'stop'`: the episode ends when the agent issues stop, a success within "
                   "the goal's radius (the protocols' rule); `'reach'`: it ends, a success, "
                   "on arrival (see Episode end)")
SUCCESS_RADIUS: Row = (f"(0, {MAX_SUCCESS_RADIUS:g}]", "metres",
                       "distance from the goal that counts as arrived")
REWARD: Row = ("a `RewardConfig`, or a dict of some of its fields, e.g. "
               "`{'progress': 10.0}`", "", "reward weights (see Rewards)")
START_JITTER: Row = ("two numbers >= 0, within the room around the start", "metres, radians",
                     "uniform perturbation of the start in x, y and heading")
OBS_KEYS: Row = ("distinct keys of the observation space", "", "the observation's keys")


class LocalHomingEnv(HomingEnv):
    """## Description

    Local visual homing. The robot was at a *home* pose and took a panoramic snapshot
    there (the goal image). It is then put down at a nearby start pose with a random
    heading and must get back home using what its panoramic camera sees: the classical
    snapshot-homing problem of insect-inspired navigation (Hong et al. 1991; Franz et al.
    1998; Yu & Kim 2011). Default scene: ``arena``, Yu & Kim's 2.4 m square with four red
    cylinders.

    ## Action space

    ``Box(-1, 1, (2,), float32)``: (forward speed, yaw rate), scaled by ``max_speed``
    (0.3 m/s) and ``max_yaw_rate`` (1.5 rad/s, counter-clockwise positive) and turned into
    wheel speeds by the unicycle model. Finite values outside ``[-1, 1]`` are clipped; NaN
    or infinite values raise ``ValueError``. The wheel motors ramp towards the commanded
    speeds at up to 2 m/s^2 of rim acceleration (``RobotConfig.wheel_acceleration``), so
    full speed is reached within about 0.15 s. With ``action_type="discrete"``: ``Discrete(4)``,
    0 forward at full speed, 1 turn left, 2 turn right, 3 stop. Each action is held for one
    control period of ``control_period`` = 0.1 s, simulated in ``physics_substeps`` = 12
    physics steps of 1/120 s (homing-gym 0.1 used 24 steps of 1/240 s: the motion tests
    pass with both, 12 halve the physics time; 8 lost 11 % of the forward speed).

    ## Observation space

    ``Dict`` with the keys listed in ``obs_keys`` (default ``("panorama", "goal")``):

    | key | space | meaning |
    |---|---|---|
    | `panorama` | `Box(0, 255, (H, W, 3), uint8)` | current cylindrical panorama, default 48 x 256 (1.41 deg/column, 1.25 deg/row) |
    | `goal` | same | panorama taken at the home pose |
    | `previous` | same | the panorama of the step before (at reset: the current one): what changed since |
    | `goal_step` | same | panorama taken `goal_step_length` (0.15 m) straight ahead of home: a second nest snapshot (Yu & Kim §II-A) |
    | `omni`, `goal_omni` | `Box(0, 255, (S, S, 3), uint8)` | catadioptric ring images, default S = 128 |
    | `signature`, `goal_signature` | `Box(0, 1, (W,), float32)` | Hong 1991 horizon signatures |
    | `odometry` | `Box(-inf, inf, (3,), float32)` | wheel-encoder path integration: pose (x, y, yaw) in the start pose's frame (``odometry_origin``) |

    Panorama convention: column ``x`` in ``[0, W)`` has bearing ``pi - 2*pi*x/W`` (radians,
    counter-clockwise from the heading): straight ahead at the centre column, directly
    behind at the edges, the horizon at row ``H/2``. See :mod:`homing_gym.render.panorama`.
    ``odometry`` starts at zero in the start pose's frame (``odometry_origin="start"``,
    the default: path integration from where the robot was put, which says nothing about
    home) and then integrates the wheel encoders, each increment scaled by
    ``1 + N(0, odometry_noise)``. ``odometry_origin="home"`` starts it at the true start
    pose in home's frame instead, as if the robot had driven out from home: the exact
    homing vector at reset, so a method given it is not homing from vision alone and its
    results must say so.

    ## Rewards

    ``progress * (d_prev - d)`` (potential-based, ``d`` the distance to home in metres)
    ``+ success`` once on success ``- collision`` on each step with contact
    ``- time`` on each step ``- wrong_stop`` on a stop outside the success radius
    (``success_on="stop"``); defaults 1.0, 10.0, 0.1, 0.01, 0 (see ``RewardConfig``).
    Each term is reported in ``info["rewards"]``.

    ## Starting state

    Home: a uniformly drawn pose with at least 0.22 m of clearance from walls and
    landmarks. Start: at a distance drawn uniformly from ``start_distance`` = (0.3, 1.5) m
    in a random direction from home, also 0.22 m clear and joined to home by a path for a
    disc of 0.22 m radius (redrawn otherwise: never in another room or a closed pocket;
    the oracle drives, and SPL measures, that path), with a uniform random heading.
    Everything is drawn from the generator seeded by ``reset(seed=...)``.
    ``reset(options={"home": (x, y, yaw), "start": (x, y, yaw)})`` sets either pose
    instead (metres, radians; e.g. to place the robot on a grid for a homing vector field;
    the start must leave room for the robot's body, the home must not lie inside a wall
    or object).
    ``env.unwrapped.set_start_distance((min, max))`` changes the range for the following
    resets (a training curriculum's hook; ``VecEnv.env_method`` reaches it through wrappers).

    ## Episode end

    With ``success_on="stop"`` (default) terminated when the agent issues stop (discrete
    action 3, or a continuous action with both components below ``stop_threshold`` = 0.05
    in magnitude), a success if it stopped within ``success_radius`` = 0.15 m of home;
    with ``success_on="reach"`` terminated, a success, as soon as the robot centre is
    within ``success_radius``. Truncated after ``max_episode_steps`` = 500 steps (50 s).

    Why "stop" by default: it is the rule of every protocol, of the matrix and of
    ``homing-suite``, so an agent's numbers from ``gym.make``'s defaults compare with
    theirs unless asked otherwise. ``success_on="reach"`` (homing-gym 0.2's default)
    stays available; every result file of the harness records the rule it used.

    ## Info

    ``pose`` (the robot's true pose), ``goal_pose`` (the current goal), ``home_pose`` (the
    episode's home, its last goal) and ``start_pose`` (the robot's pose right after
    reset), all (x, y, yaw) in metres and radians; ``distance_to_goal`` (m),
    ``is_success``, ``collision`` (contact this step), ``collisions`` (steps with contact
    so far), ``rewards`` (the reward terms). Ground truth: for metrics, not for agents.
    The scene of the episode is ``env.unwrapped.scene`` (for path-length metrics).

    ## Arguments

    ``gym.make("homing_gym/LocalHoming-v0", **kwargs)`` with the arguments below and
    ``max_episode_steps``: the task's, then the env core's, shared by every env id
    (:class:`~homing_gym.config.EnvConfig`; the table is written from the code).

    ## Version history

    * v0: initial release.
    """

    ARGUMENTS: dict[str, Row] = {
        "scene": (SCENE[0] + ", e.g. `'random_arena'`, `'random_rooms'`, `'random_nature'`",
                  "", SCENE[2]),
        "start_distance": ("(min, max) with success_radius <= min <= max, fitting the scene",
                           "metres", "distance of the start from home, drawn uniformly"),
        "success_radius": SUCCESS_RADIUS, "success_on": SUCCESS_ON, "reward": REWARD}

    def __init__(self, scene: str | Scene = "arena", *,
                 start_distance: tuple[float, float] = (0.3, 1.5),
                 success_radius: float = 0.15, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig(), **kwargs):
        check_env_kwargs(type(self), kwargs)
        task = LocalHomingTask(start_distance=start_distance, success_radius=success_radius,
                               success_on=success_on, reward=reward)
        super().__init__(task, scene, **kwargs)

    def set_start_distance(self, start_distance: tuple[float, float],
                           success_radius: float | None = None) -> None:
        """Draw the starts of the following resets ``start_distance`` = (min, max) metres
        from home (the episode under way keeps its start) and, when given, judge arrival
        with ``success_radius`` metres from the next step on: the hook of a training
        curriculum, e.g. ``vec_env.env_method("set_start_distance", (0.2, 0.6))``. Checked
        as the arguments ``start_distance`` and ``success_radius`` are (also against the
        current scene); a bad value raises ``ValueError`` and changes nothing."""
        previous = self.task.start_distance, self.task.success_radius
        self.task.set_start_distance(start_distance, success_radius)
        try:
            self.task.check_scene(self.scene)
        except ValueError:
            self.task.start_distance, self.task.success_radius = previous
            raise


class RouteFollowingEnv(HomingEnv):
    """## Description

    Route following by successive local homing (Hong et al. 1991 §5). A route of target
    places was taught by taking a panoramic snapshot at each: by default 17 targets 1 ft
    (0.3048 m) apart along the centre line of the ``hallway`` scene, all facing along the
    corridor. The robot starts ``spacing`` (1 ft) before the first target and must home to each target
    in turn; the goal observation is the snapshot of the current target and switches to
    the next one when a target is reached. ``route`` gives any other route, curved or
    not, in any scene: the robot's start point followed by the targets; ``route="random"``
    draws a new curved route in each episode's world.

    ## Action space

    As ``LocalHoming-v0``: ``Box(-1, 1, (2,), float32)`` (forward speed, yaw rate; max
    0.3 m/s and 1.5 rad/s) or ``Discrete(4)`` with ``action_type="discrete"``; control
    period 0.1 s.

    ## Observation space

    As ``LocalHoming-v0`` (``obs_keys``): ``panorama``, ``goal`` (the current target's
    snapshot), optional ``previous``, ``omni``, ``goal_omni``, ``signature``,
    ``goal_signature``, ``odometry`` (zero at the start; with ``odometry_origin="home"``
    the pose in the frame of the last target), and, only when asked for, the route's teaching views:

    | key | space | meaning |
    |---|---|---|
    | `route_views` | `Box(0, 255, (K, H, W, 3), uint8)` | the panoramas taken while the robot was led along the route (the views a familiarity method learns from, Baddeley et al. 2012), in travel order: `K = ceil(L / route_view_spacing) + 1` places evenly spread over the route's length `L`, the first at the start point, the last at the last target, each facing the direction of travel there (column `W/2`); constant during an episode |

    ``route_views`` are taken at reset under the snapshots' lighting, in the episode's
    world (once per world: a fixed scene's are taken once), from the route as taught
    (the start point before its jitter), so they cost ``K`` renders per new world and
    ``K`` panoramas in every observation: ask for them with ``obs_keys``, e.g.
    ``obs_keys=("panorama", "goal", "route_views")``. For the default hallway route
    (5.18 m) and ``route_view_spacing`` = 0.1 m, ``K`` = 53. A route shorter than
    ``route_view_spacing`` (fewer than two views) or one needing more than 512 views
    raises ``ValueError`` naming ``route_view_spacing``.

    ## Rewards

    ``progress * (d_prev - d)`` towards the current target (restarted at each switch)
    ``+ waypoint`` for each intermediate target reached within the radius ``+ success``
    for the last one ``- collision`` on each step with contact ``- time`` on each step
    ``- wrong_stop`` on a stop outside the radius (``success_on="stop"``); defaults 1.0,
    1.0, 10.0, 0.1, 0.01, 0. Terms in ``info["rewards"]``.

    ## Starting state

    ``spacing`` (1 ft) before the first target, on the route line (with ``route``: its first point),
    perturbed uniformly by up to ``start_jitter`` = (0.05 m, 10 degrees) in x, y and
    heading, drawn from the seed.
    With ``lighting_change > 0`` the lighting of the run differs from the lighting of
    the snapshots.

    ## Episode end

    ``success_on="stop"`` (default; why: ``LocalHoming-v0``): the agent signals arrival
    with the stop action (discrete 3, or both continuous components below
    ``stop_threshold``); the target is left whatever the distance, which is recorded as
    its error. ``success_on="reach"``: a target is reached when the robot centre comes
    within ``success_radius`` = 0.1 m of it. Terminated after the last target; a success if it was reached within
    ``success_radius``. Truncated after 1000 steps.

    ## Info

    As ``LocalHoming-v0`` (``goal_pose`` and ``distance_to_goal`` refer to the current
    target), plus ``target_index`` (0-based index of the current target) and
    ``target_errors`` (distance in metres at which each finished target was left).

    ## Arguments

    The task's arguments, then the env core's, as in ``LocalHoming-v0`` (the table
    below). ``route``: a sequence of at least two points ``(x, y)`` or ``(x, y, yaw)``
    (metres, radians counter-clockwise from +x), e.g. ``[(1, 0), (2, 0.3), (3, 0)]``, or
    the path of a ``.csv``, ``.npy`` or ``.json`` file of such rows, at most 10,000: the
    first is where the robot starts, the others are the targets in order; a missing yaw is
    the direction of travel from the previous point; consecutive points at least 0.05 m
    apart, every point inside the scene with room for the robot's body, 0.16 m of
    clearance, and joined to the next by a path for it; it replaces the straight route,
    so ``n_targets`` and ``spacing`` must then keep their defaults. ``route="random"``:
    each episode draws its own route from the seed, ``n_targets`` legs of ``spacing``
    metres, the first in any direction, each turning by up to 30 degrees from the last,
    every point and leg 0.18 m clear of walls and objects, in any scene (built-in,
    procedural, a mesh); a scene that cannot hold one raises ``ValueError`` at reset. A
    bad ``route`` raises ``ValueError``.

    ## Version history

    * v0: initial release.
    """

    ARGUMENTS: dict[str, Row] = {
        "scene": (SCENE[0] + " with `metadata['route_origin']`, or any with `route`", "",
                  SCENE[2]),
        "n_targets": ("integer in [1, 9,999]", "", "targets of the straight or random route"),
        "spacing": ("[0.05, 100]", "metres",
                    "distance between the straight or random route's targets"),
        "route": ("`None`, points, a file or `\"random\"` (see above)", "metres, radians",
                  "any other route: the start, then the targets"),
        "route_view_spacing": ("[0.01, 2], at most the route's length", "metres",
                               "largest distance between the teaching views "
                               "`route_views`"),
        "start_jitter": START_JITTER, "success_radius": SUCCESS_RADIUS,
        "success_on": SUCCESS_ON, "reward": REWARD}

    def __init__(self, scene: str | Scene = "hallway", *, n_targets: int = 17,
                 spacing: float = FOOT,
                 route: Sequence[Sequence[float]] | str | os.PathLike | None = None,
                 route_view_spacing: float = ROUTE_VIEW_SPACING,
                 start_jitter: tuple[float, float] = (0.05, 0.1745),
                 success_radius: float = 0.1, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig(), **kwargs):
        check_env_kwargs(type(self), kwargs)
        task = RouteFollowingTask(n_targets=n_targets, spacing=spacing, route=route,
                                  route_view_spacing=route_view_spacing,
                                  start_jitter=start_jitter, success_radius=success_radius,
                                  success_on=success_on, reward=reward)
        super().__init__(task, scene, **kwargs)


class LongRangeHomingEnv(HomingEnv):
    """## Description

    Long-range visual homing (Bekris, Argyros & Kavraki §3 and §5, Fig. 12). The robot
    stands at home, where the goal panorama is taken. Each episode starts with an
    *outbound phase*: the env itself drives the robot along a seeded route of
    ``route_length`` = 8 m (polyline legs of 0.8-2 m turning by up to 120 degrees, every
    point at least 0.3 m clear of walls and objects) while the agent watches every frame,
    as the paper's robot "after executing a predetermined set of motion commands, reaches
    position G, covering a distance of approximately eight meters". Then the *homing
    phase* begins and the agent must bring the robot back home from the end of the route,
    where home usually shares no view features with the current panorama. Default scene:
    ``lab`` (6 x 5 m, three coloured poster columns, door, desk, boxes, textured walls);
    any scene with room for the route works.

    ## Action space

    As ``LocalHoming-v0``: ``Box(-1, 1, (2,), float32)`` (forward speed, yaw rate; max
    0.3 m/s and 1.5 rad/s) or ``Discrete(4)`` with ``action_type="discrete"``; control
    period 0.1 s. During the outbound phase actions are validated (a bad action still
    raises ``ValueError``) and ignored.

    ## Observation space

    As ``LocalHoming-v0`` (``obs_keys``, default ``("panorama", "goal", "phase")``), plus:

    | key | space | meaning |
    |---|---|---|
    | `phase` | `Discrete(2)` | 0 outbound (the env drives), 1 homing (the agent drives) |

    ``goal`` is the home snapshot throughout. ``odometry`` (if asked for) integrates the
    wheel encoders from home, where the episode starts, over the outbound route too
    (both origins are home here).

    ## Rewards

    0 during the outbound phase. Then as ``LocalHoming-v0``: ``progress * (d_prev - d)``
    ``+ success`` once ``- collision`` per step with contact ``- time`` per step
    ``- wrong_stop`` on a stop away from home (``success_on="stop"``); defaults 1.0, 10.0,
    0.1, 0.01, 0. Terms in ``info["rewards"]``.

    ## Starting state

    Home: a uniformly drawn pose with at least 0.3 m of clearance; the robot starts there.
    The route is drawn from the same seed (``reset(seed=...)``). The outbound driver
    turns on the spot towards the next waypoint when it is more than 0.2 rad off the
    heading and otherwise drives at ``outbound_speed`` = 0.15 m/s, steering at up to
    ``outbound_yaw_rate`` = 0.5 rad/s (slow, like the paper's 4 cm/s and 3 deg/s, so that
    features move little between frames); a waypoint is passed within 5 cm. An 8 m route
    takes about 600-800 steps. ``reset(options={"home": ..., "start": ...})`` as in
    ``LocalHoming-v0``; the route then starts at ``start``.

    ## Episode end

    Never during the outbound phase. In the homing phase: ``success_on="stop"`` (default;
    why: ``LocalHoming-v0``) terminated when the agent issues stop, a success if within
    ``success_radius`` = 0.2 m of home; ``success_on="reach"`` terminated, a success, when
    the robot centre comes within ``success_radius``. Truncated after ``max_episode_steps`` =
    2500 steps in all (outbound steps included).

    ## Info

    As ``LocalHoming-v0`` (``goal_pose`` is home), plus ``phase``, ``outbound_steps``
    (steps of the outbound phase so far) and ``route`` (the waypoints, ``(K, 2)`` metres,
    starting at home). Ground truth: for metrics, not for agents.

    ## Arguments

    The task's arguments, then the env core's, as in ``LocalHoming-v0`` (the table
    below). A scene that cannot hold the route raises ``ValueError`` at reset.

    ## Version history

    * v0: initial release.
    """

    ARGUMENTS: dict[str, Row] = {
        "scene": (SCENE[0] + " with room for the route", "", SCENE[2]),
        "route_length": ("[0.5, 30]", "metres", "length of the outbound route"),
        "outbound_speed": ("> 0, at most `max_speed`", "m/s", "the outbound driver's speed"),
        "outbound_yaw_rate": ("> 0, at most `max_yaw_rate`", "rad/s",
                              "the outbound driver's largest yaw rate"),
        "success_radius": SUCCESS_RADIUS, "success_on": SUCCESS_ON, "reward": REWARD,
        "obs_keys": OBS_KEYS}

    def __init__(self, scene: str | Scene = "lab", *, route_length: float = 8.0,
                 outbound_speed: float = 0.15, outbound_yaw_rate: float = 0.5,
                 success_radius: float = 0.2, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig(),
                 obs_keys: tuple[str, ...] | list[str] = ("panorama", "goal", "phase"),
                 **kwargs):
        check_env_kwargs(type(self), kwargs)
        task = LongRangeHomingTask(route_length=route_length, outbound_speed=outbound_speed,
                                   outbound_yaw_rate=outbound_yaw_rate,
                                   success_radius=success_radius, success_on=success_on,
                                   reward=reward)
        super().__init__(task, scene, obs_keys=obs_keys, **kwargs)
        task.check_limits(self.robot_config)


class LandmarkNavigationEnv(HomingEnv):
    """## Description

    Landmark navigation (Briggs, Scharstein et al. 2000, §4). Barcoded self-similar
    landmarks hang on the walls of the ``corridors`` scene (four rooms off a corridor, 14
    panels with ids 0-13; :mod:`homing_gym.selfsimilar`). The goal is a landmark id; the
    robot must go and stand in front of that landmark, using only what it sees. The
    robot knows the landmark design (the pattern, the barcode, the panel size), not the
    map: a method learns where landmarks are by exploring (the paper's visibility graph,
    controller ``selfsimilar``).

    ## Action space

    As ``LocalHoming-v0``: ``Box(-1, 1, (2,), float32)`` (forward speed, yaw rate; max
    0.3 m/s and 1.5 rad/s) or ``Discrete(4)`` with ``action_type="discrete"``; control
    period 0.1 s.

    ## Observation space

    ``Dict`` with the keys in ``obs_keys`` (default ``("panorama", "goal_id")``): every
    key of ``LocalHoming-v0`` except that ``goal`` is the panorama at the standing pose
    in front of the goal landmark (a cue a homing method could use, not the paper's),
    plus:

    | key | space | meaning |
    |---|---|---|
    | `goal_id` | `Box(0, 1, (31,), float32)` | one-hot id of the goal landmark (ids 0-30, all a barcode can carry) |
    | `view` | `Box(0, 255, (h, w, 3), uint8)` | forward perspective camera at the panoramic camera's place: ``view_size`` = (320, 240) pixels, ``view_hfov_deg`` = 60 (Briggs et al. use 320 x 240 and 640 x 480 images) |

    The panorama follows the usual convention (column ``x`` has bearing
    ``pi - 2*pi*x/W``); landmarks are detectable in it only at high resolution (e.g.
    ``panorama_shape=(192, 2048)``: the detector needs patterns about 30 pixels wide).

    ## Rewards

    ``progress * (d_prev - d)``, ``d`` the distance (m) to the standing pose ``standoff``
    = 0.8 m in front of the goal landmark, ``+ success`` on success ``- collision`` per
    step with contact ``- time`` per step ``- wrong_stop`` on a stop that is not a
    success; defaults 1.0, 10.0, 0.1, 0.01, 0 (``RewardConfig``). Terms in
    ``info["rewards"]``.

    ## Starting state

    The goal id is drawn uniformly among the landmarks present; the start uniformly on
    the floor of the rooms and the corridor (at least 0.25 m from walls and objects,
    joined to the goal's standing pose by a path for a disc of that radius, not already
    in front of the goal), with a uniform heading. With ``remove_landmarks`` =
    q > 0 each landmark is missing from the episode with probability q (never all); with
    ``occlude_landmarks`` = q > 0 each remaining one is partly hidden with probability q
    by a dark board (0.3 m wide, 0.8 m tall) standing 0.3 m in front of it, shifted
    sideways at random. All drawn from the ``reset(seed=...)`` generator.

    ## Episode end

    *In front of* the goal: robot centre at most ``max_distance`` = 1.2 m from the panel
    centre, within ``max_angle_deg`` = 30 degrees of the panel's normal as seen from the
    panel, and the panel within 30 degrees of the robot's heading. With
    ``success_on="stop"`` (default; why: ``LocalHoming-v0``) the episode terminates when
    the agent issues stop, a success if it is in front of the goal then; with ``"reach"``
    it terminates, a success, as soon as the robot is in front of the goal. Truncated after 3000 steps
    (300 s).

    ## Info

    As ``LocalHoming-v0`` (``goal_pose`` is the standing pose, ``distance_to_goal`` the
    distance to it), plus ``goal_id``. Ground truth: for metrics, not for agents.

    ## Arguments

    The task's arguments, then the env core's, as in ``LocalHoming-v0`` (the table
    below).

    ## Version history

    * v0: initial release.
    """

    ARGUMENTS: dict[str, Row] = {
        "scene": (SCENE[0] + " with `metadata['landmarks']` and `['rooms']`", "", SCENE[2]),
        "max_distance": ("> 0", "metres", "farthest from the panel that is in front of it"),
        "max_angle_deg": ("(0, 90]", "degrees", "widest angle off the panel's normal"),
        "standoff": ("> 0", "metres", "the standing pose's distance in front of the panel"),
        "success_on": SUCCESS_ON, "reward": REWARD,
        "remove_landmarks": ("[0, 1]", "", "probability that a landmark is missing"),
        "occlude_landmarks": ("[0, 1]", "", "probability that a landmark is partly hidden"),
        "view_size": ("(width, height) integers in [16, 4096]", "pixels",
                      "size of the `view` image"),
        "view_hfov_deg": ("[5, 150]", "degrees", "horizontal field of view of `view`"),
        "obs_keys": OBS_KEYS}

    def __init__(self, scene: str | Scene = "corridors", *, max_distance: float = 1.2,
                 max_angle_deg: float = 30.0, standoff: float = 0.8,
                 success_on: str = "stop", reward: RewardConfig = RewardConfig(),
                 remove_landmarks: float = 0.0, occlude_landmarks: float = 0.0,
                 view_size: tuple[int, int] = (320, 240), view_hfov_deg: float = 60.0,
                 obs_keys: tuple[str, ...] | list[str] = ("panorama", "goal_id"), **kwargs):
        check_env_kwargs(type(self), kwargs)
        for name, value in (("remove_landmarks", remove_landmarks),
                            ("occlude_landmarks", occlude_landmarks)):
            require_number(name, value, 0, 1, "(a probability)")
        task = LandmarkNavigationTask(max_distance=max_distance, max_angle_deg=max_angle_deg,
                                      standoff=standoff, success_on=success_on, reward=reward,
                                      view_size=require_sequence("view_size", view_size, 2,
                                                                 "(width, height) integers"),
                                      view_hfov_deg=view_hfov_deg)
        factory = scene_factory(scene)
        if remove_landmarks > 0 or occlude_landmarks > 0:
            base = factory
            factory = SceneFactory(
                build=lambda rng: changed_landmarks(base.build(rng), rng, remove_landmarks,
                                                    occlude_landmarks),
                randomised=True, description=f"{base.description}, landmarks changed")
        super().__init__(task, factory, obs_keys=obs_keys, **kwargs)


class WorkLocationsEnv(HomingEnv):
    """## Description

    Travel between work locations of a home (Shiraishi & Sawasaki, "multi-resolution
    image matching", §2-§4). A person taught the robot its *work locations* (including
    its home) and the *travel paths* between them; now the robot stands at one work
    location and must travel along the taught path to a named other one and stop there,
    using only what its camera sees and what it recorded while being taught. Default
    scene: ``house`` (living room, kitchen, bedroom; work locations ``home``,
    ``kitchen``, ``bedroom``; see :mod:`homing_gym.scenes.house`). Accuracy of the stop is
    the point: by default the episode ends when the agent stops (``success_on="stop"``),
    a success within 0.1 m (the paper: arrival "generally recognized with an accuracy of
    10 centimeters or better").

    Teaching (:mod:`homing_gym.teaching`), done by the env in the scene as it was on the
    teaching day, the first time a path is used, and cached: along the path a
    low-resolution panorama every 0.47 m (§4(1)) and at each corner and the end, each
    centred on the desired direction of travel; at the target location a
    *multiresolution feature image map* (§3(2), Fig. 2): its low-resolution panorama
    (centred on the location's heading), high-resolution templates of up to 10
    characteristic points (picture centres that the camera sees unoccluded 0.8-6 m away,
    spread around the horizon) and their positions in the low-resolution panorama, with
    their 3-D indoor coordinates. The paper's person enters those coordinates by hand;
    here they are taken from the scene (``metadata["feature_points"]``), exact.
    Low resolution: grey levels reduced by ``teach_levels`` = 2 steps of a Gaussian
    pyramid (``cv2.pyrDown``): 16 x 128 for the default 64 x 512 panorama.

    ## Action space

    As ``LocalHoming-v0``: ``Box(-1, 1, (2,), float32)`` (forward speed, yaw rate; max
    0.3 m/s and 1.5 rad/s; negative speed drives backwards) or ``Discrete(4)`` with
    ``action_type="discrete"``; control period 0.1 s.

    ## Observation space

    ``Dict`` with the keys in ``obs_keys`` (default: ``panorama`` and every taught key
    below). ``panorama`` is the current view, default ``panorama_shape`` = (64, 512):
    0.70 degrees per column, 0.94 per row (the high resolution the templates need). The
    taught keys are constant during an episode; ``h x w`` is the low-resolution shape,
    ``t`` = ``template_size``:

    | key | space | meaning |
    |---|---|---|
    | `path_panoramas` | `Box(0, 255, (32, h, w), uint8)` | the path's low-resolution grey panoramas in travel order, each centred on the desired direction of travel there (column `w/2`); rows past `path_count` are zero |
    | `path_count` | `Discrete(33)` | number of taught places on the path; the last is the target location |
    | `map_panorama` | `Box(0, 255, (h, w), uint8)` | (1-1): low-resolution panorama at the target location, centred on its heading |
    | `map_templates` | `Box(0, 255, (10, t, t), uint8)` | (1-2): high-resolution grey templates of the characteristic points, each centred on its point |
    | `map_template_xy` | `Box(0, max(h, w), (10, 2), float32)` | (1-3): continuous (column, row) of each point in `map_panorama` |
    | `map_points` | `Box(-inf, inf, (10, 3), float32)` | the points' 3-D indoor coordinates (m) |
    | `map_count` | `Discrete(11)` | number of characteristic points; entries past it are zero |
    | `map_pose` | `Box(-inf, inf, (3,), float32)` | the target location as taught: (x, y, yaw), m and rad, indoor frame |

    Also every key of ``LocalHoming-v0`` (``goal`` is the panorama at the target
    location in today's scene). Panorama convention: column ``x`` has bearing
    ``pi - 2*pi*x/W``, horizon at row ``H/2``; the same holds for the low-resolution
    images with their own ``w`` and ``h``.

    ## Rewards

    ``progress * (d_prev - d)`` (``d`` the distance in metres to the target location)
    ``+ success`` once on success ``- collision`` per step with contact ``- time`` per
    step ``- wrong_stop`` on a stop outside the success radius; defaults 1.0, 10.0, 0.1,
    0.01, 0 (``RewardConfig``). Terms in ``info["rewards"]``.

    ## Starting state

    The path (start and target location) is drawn uniformly among the taught paths
    allowed by ``start_location`` and ``goal_location`` (each a work location name or
    ``None``: any). The robot stands at the start location perturbed uniformly by up to
    ``start_jitter`` = (0.05 m, 5 degrees) in x, y and heading. With ``daily_changes`` =
    s > 0 the scene of each episode is today's house, drawn from the seed: each small
    object removed with probability s/3 or moved (up to 0.4 m, any yaw) with probability
    s/2, and round(3 s) new small objects put down at free places, never on a path or a
    work location (problem (b-1) of §2; :mod:`homing_gym.scenes.daily_changes`); the
    taught data always shows the house as taught. ``reset(options={"start": pose})``
    places the robot elsewhere (e.g. 1 m before the target); option ``home`` raises
    ``ValueError`` (the target is the named location). Everything is reproducible with
    ``reset(seed=...)``.

    ## Episode end

    ``success_on="stop"`` (default): terminated when the agent issues stop (discrete
    action 3, or both continuous components below ``stop_threshold`` = 0.05), a success
    if the robot centre is within ``success_radius`` = 0.1 m of the target location.
    ``success_on="reach"``: terminated, a success, once within ``success_radius``.
    Truncated after 1500 steps (150 s).

    ## Info

    As ``LocalHoming-v0`` (``goal_pose`` is the target location), plus
    ``start_location``, ``goal_location`` (names) and ``places`` (``(K, 3)``: the taught
    places of the path, x, y and desired direction of travel). Ground truth: for metrics,
    not for agents.

    ## Arguments

    The task's arguments, then the env core's, as in ``LocalHoming-v0`` (the table
    below). Unknown location names, a path with more than 32 places, or values out of
    range raise ``ValueError``.

    ## Version history

    * v0: initial release.
    """

    ARGUMENTS: dict[str, Row] = {
        "scene": (SCENE[0] + " with `metadata['work_locations']`, `['paths']`, "
                  "`['feature_points']`", "", SCENE[2]),
        "start_location": ("a work location's name, or `None`: any", "",
                           "where the robot starts"),
        "goal_location": ("a work location's name, or `None`: any", "",
                          "where it must travel to"),
        "start_jitter": START_JITTER,
        "daily_changes": ("[0, 1]", "", "strength of the day's changes (0: the house as "
                          "taught)"),
        "teach_levels": ("integer in [1, 4]", "pyramid steps", "low resolution of the taught "
                         "images"),
        "place_spacing": ("[0.05, 2]", "metres", "distance between the path's taught places"),
        "template_size": ("odd integer in [5, 63]", "pixels", "side of the templates"),
        "max_points": ("integer in [2, 10]", "", "characteristic points per location"),
        "success_radius": SUCCESS_RADIUS, "success_on": SUCCESS_ON, "reward": REWARD,
        "panorama_shape": ("as `LocalHoming-v0`'s", "pixels", "panorama size (H, W)"),
        "obs_keys": OBS_KEYS}

    def __init__(self, scene: str | Scene = "house", *, start_location: str | None = None,
                 goal_location: str | None = None,
                 start_jitter: tuple[float, float] = (0.05, 0.0873),
                 daily_changes: float = 0.0, teach_levels: int = 2,
                 place_spacing: float = PLACE_SPACING, template_size: int = 17,
                 max_points: int = MAX_POINTS, success_radius: float = 0.1,
                 success_on: str = "stop", reward: RewardConfig = RewardConfig(),
                 panorama_shape: tuple[int, int] = (64, 512),
                 obs_keys: tuple[str, ...] | list[str] = ("panorama", *TAUGHT_KEYS),
                 **kwargs):
        check_env_kwargs(type(self), kwargs)
        require_number("daily_changes", daily_changes, 0, 1, "(0: the house as taught)")
        panorama_shape = require_sequence("panorama_shape", panorama_shape, 2, "(H, W) integers")
        CameraConfig(panorama_shape=panorama_shape)   # checks the shape first
        task = WorkLocationsTask(panorama_shape, start_location, goal_location,
                                 start_jitter=start_jitter, teach_levels=teach_levels,
                                 spacing=place_spacing, template_size=template_size,
                                 max_points=max_points, success_radius=success_radius,
                                 success_on=success_on, reward=reward)
        factory = scene_factory(scene)
        task.taught_scene = factory.build(np.random.default_rng(0))
        if daily_changes > 0:
            base = factory
            factory = SceneFactory(
                build=lambda rng: daily_changes_of(base.build(rng), rng, daily_changes),
                randomised=True, description=f"{base.description}, daily changes")
        super().__init__(task, factory, panorama_shape=panorama_shape, obs_keys=obs_keys,
                         **kwargs)
