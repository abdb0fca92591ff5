"""Protocols: named, versioned episode suites under one success rule.

A :class:`Protocol` fixes everything a table row depends on except the method: the
settings (env id and env kwargs, e.g. one per scene), how each setting's episodes are
drawn (seeds, and start/home poses where the paper fixes them), the default number of
episodes, the methods it applies to, and the paper's claim to set beside our number.

**One success rule for every row**: every setting runs with ``success_on="stop"``: an
episode succeeds when the agent itself declares arrival (its stop action, or a
continuous action below the stop threshold) within ``success_radius`` of the goal: 0.15 m,
0.10 m in ``shiraishi-house`` (the WorkLocations env's radius, the paper's 10 cm); in
``briggs-corridors`` the place is the task's own ("in front of the landmark",
``Protocol.place``). "Reached" (a second column) counts episodes that came within the
radius at any time, stopped or not (not given where the place rule is not a radius).

``homing-eval --protocol NAME --policy METHOD`` runs one method on a protocol;
``homing-suite --protocols ...`` runs every applicable method on each and writes the
methods x protocols matrix. Changing what a protocol does means a new ``version``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from homing_gym.scenes import scene_factory
from homing_gym.scenes.base import clearance

#: The renderer and physics every version-1 protocol was measured with (homing-gym 0.1's
#: env defaults: TinyRenderer, 1/240 s physics steps), pinned so that its cells reproduce
#: under later defaults.
V1_SIMULATION = {"renderer": "tiny", "physics_substeps": 24}
#: The renderer and physics of version-2 protocols: homing-gym 0.2's defaults (the ray
#: caster, 1/120 s physics steps).
V2_SIMULATION = {"renderer": "raycast", "physics_substeps": 12}
#: (seed, start pose or None, home pose or None): one episode; None lets the env draw it.
Task = tuple
#: The name standing for every shipped PPO policy trained on the protocol's env.
POLICIES = "policies"
SUCCESS_RADIUS = 0.15


def scene_named(name: str, seed: int = 0):
    """The :class:`~homing_gym.scenes.base.Scene` a scene name builds (seeded)."""
    return scene_factory(name).build(np.random.default_rng(seed))


def ring_starts(scene: str, home: Sequence[float], bins: Sequence[tuple[float, float]],
                per_bin: int, seed: int, margin: float = 0.22) -> list[Task]:
    """``per_bin`` episodes per start-distance bin ``[lo, hi)`` metres around a fixed
    ``home`` (x, y, yaw): start positions uniform in distance and direction with at least
    ``margin`` metres of clearance, start headings uniform (Yu & Kim, Fig. 6). Seeds
    ``seed + 1000 * bin + i``."""
    world = scene_named(scene)
    rng = np.random.default_rng(seed)
    tasks: list[Task] = []
    for b, (lo, hi) in enumerate(bins):
        found = 0
        while found < per_bin:
            d, a = rng.uniform(lo, hi), rng.uniform(-np.pi, np.pi)
            xy = (home[0] + d * math.cos(a), home[1] + d * math.sin(a))
            if clearance(world, xy) >= margin:
                start = (xy[0], xy[1], float(rng.uniform(-np.pi, np.pi)))
                tasks.append((seed + 1000 * b + found, start, tuple(home)))
                found += 1
    return tasks


def marked_goal_starts(scene: str, per_goal: int, seed: int, goal_yaw: float,
                       distance: tuple[float, float] = (0.5, 3.0),
                       margin: float = 0.3) -> list[Task]:
    """``per_goal`` episodes to each marked position of ``scene`` (its metadata
    ``"marked"``, e.g. the lab's A-F), from random starts ``distance`` metres away with
    ``margin`` metres of clearance and random headings (Bekris et al., Fig. 11); the goal
    heading is ``goal_yaw`` (radians)."""
    world = scene_named(scene)
    rng = np.random.default_rng(seed)
    (xmin, ymin), (xmax, ymax) = world.bounds
    tasks: list[Task] = []
    for g, point in enumerate(world.metadata["marked"].values()):
        found = 0
        while found < per_goal:
            xy = (float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)))
            if clearance(world, xy) < margin or not (
                    distance[0] <= math.dist(xy, point[:2]) <= distance[1]):
                continue
            tasks.append((seed + 1000 * g + found, (*xy, float(rng.uniform(-np.pi, np.pi))),
                          (float(point[0]), float(point[1]), goal_yaw)))
            found += 1
    return tasks


def common_heading_starts(scene: str, distance: float, n: int, seed: int,
                          margin: float = 0.25) -> list[Task]:
    """``n`` episodes with a random home (uniform over the scene, random heading) and a
    start ``distance`` metres from it in a random direction *with the home's heading*
    (Hong et al.: the robot does not rotate), both with ``margin`` metres of clearance.
    Seeds ``seed + i``."""
    world = scene_named(scene)
    rng = np.random.default_rng(seed)
    (xmin, ymin), (xmax, ymax) = world.bounds
    tasks: list[Task] = []
    while len(tasks) < n:
        yaw = float(rng.uniform(-np.pi, np.pi))
        home = (float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)), yaw)
        a = rng.uniform(-np.pi, np.pi)
        start = (home[0] + distance * math.cos(a), home[1] + distance * math.sin(a), yaw)
        if min(clearance(world, home[:2]), clearance(world, start[:2])) >= margin:
            tasks.append((seed + len(tasks), start, home))
    return tasks


@dataclass(frozen=True)
class Setting:
    """One part of a protocol: ``env_id`` with ``env_kwargs`` (``success_on="stop"`` is
    added) under ``simulation`` (renderer and physics, pinned: :data:`V1_SIMULATION`
    by default), its episodes from ``tasks(episodes, seed)`` or, without it, seeds only
    (the env draws start and home)."""

    label: str
    env_id: str
    env_kwargs: dict = field(default_factory=dict)
    tasks: Callable[[int, int], list[Task]] | None = None
    simulation: dict = field(default_factory=lambda: dict(V1_SIMULATION))

    def kwargs(self) -> dict:
        return {**self.simulation, **self.env_kwargs, "success_on": "stop"}

    def episode_tasks(self, episodes: int, seed: int) -> list[Task]:
        if self.tasks is None:
            return [(s, None, None) for s in range(seed, seed + episodes)]
        return self.tasks(episodes, seed)


@dataclass(frozen=True)
class Protocol:
    """A named, versioned episode suite; see the module docstring."""

    name: str
    version: int
    summary: str
    settings: tuple[Setting, ...]
    methods: tuple[str, ...]
    episodes: int = 10                 # per setting, the default of the matrix
    seed: int = 0
    paper: str = ""                    # the paper's claim, beside our number
    privileged: str = ""               # anything beyond pixels the protocol gives
    place: str = ""                    # a place rule other than the radius (the task's)

    @property
    def label(self) -> str:
        return f"{self.name} v{self.version}"

    def success_radius(self, setting: Setting) -> float:
        return float(setting.env_kwargs.get("success_radius", SUCCESS_RADIUS))

    def command(self, method: str, episodes: int | None = None) -> str:
        """The ``homing-eval`` command that reproduces one matrix cell."""
        extra = f" --episodes {episodes}" if episodes not in (None, self.episodes) else ""
        return f"homing-eval --protocol {self.name} --policy {method}{extra} --out OUT.json"


def _hong_one_foot(episodes: int, seed: int) -> list[Task]:
    return common_heading_starts("hallway", FOOT, episodes, seed)


def _yukim_nest(episodes: int, seed: int) -> list[Task]:
    bins = ((0.3, 0.6), (0.6, 0.9), (0.9, 1.2), (1.2, 1.4))
    return ring_starts("arena", NEST, bins, max(1, math.ceil(episodes / len(bins))), seed)


def _bekris_goals(episodes: int, seed: int) -> list[Task]:
    return marked_goal_starts("lab", max(1, math.ceil(episodes / 6)), seed, goal_yaw=0.5)


#: Hong et al.'s step between snapshots, and the start distance of their demonstration (§5).
FOOT = 0.3048
#: Yu & Kim's nest: the arena's centre, among the four cylinders (§IV).
NEST = (0.0, 0.0, 0.0)
LOCAL = "homing_gym/LocalHoming-v0"
HOMING_METHODS = ("oracle", "random", "snapshot", "warping", "distance", POLICIES)
#: Held out from every shipped policy's training: seeds of the procedural worlds far from
#: the training seeds, and scenes it never saw.
UNSEEN_SEED = 10_000_000
#: The worlds of ``local-common`` v2: the paper scenes and the procedural worlds.
COMMON_SCENES = ("arena", "hallway", "lab", "house", "random_rooms", "random_nature")
PROCEDURAL = ("random_arena", "random_rooms", "random_nature")


def _held_out(episodes: int, seed: int) -> list[Task]:
    """Seeds from :data:`UNSEEN_SEED` on: procedural worlds no policy trained on."""
    return [(UNSEEN_SEED + seed + i, None, None) for i in range(episodes)]

PROTOCOLS: dict[str, Protocol] = {p.name: p for p in (
    Protocol(
        "hong1991", 1, "Hong et al.: the hallway, a synchro-drive robot (it translates "
        "without turning), starts 1 ft (0.3048 m) from a random home with the home's "
        "heading; panorama 60 x 360 (1 deg per column)",
        (Setting("hallway, 1 ft", LOCAL,
                 {"scene": "hallway", "drive": "synchro", "panorama_shape": [60, 360],
                  "max_episode_steps": 200}, _hong_one_foot),),
        ("snapshot", "warping", "oracle", "random"), episodes=10,
        paper="§5: a 17-target route, targets 1 ft apart, traversed: every 1-ft homing "
              "succeeded (>= 95% expected)"),
    Protocol(
        "yukim", 1, "Yu & Kim: the arena, the nest among the four landmarks, starts "
        "0.3-1.4 m away in the four distance bins of Fig. 6, random headings",
        (Setting("arena, nest", LOCAL, {"scene": "arena", "max_episode_steps": 300},
                 _yukim_nest),),
        ("distance", "warping", "snapshot", "oracle", "random", POLICIES), episodes=12,
        paper="Fig. 6: distance estimation homes in most runs up to 1.4 m"),
    Protocol(
        "yukim-anywhere", 1, "the arena with homes anywhere (not the paper's setting: "
        "most homes lie outside the landmarks' quadrilateral)",
        (Setting("arena, anywhere", LOCAL, {"scene": "arena"}),),
        HOMING_METHODS, episodes=10, paper="(not a paper setting)"),
    Protocol(
        "bekris-lab", 1, "Bekris et al.: the lab, goals A-F, random starts 0.5-3 m away "
        "(Fig. 11)",
        (Setting("lab, A-F", LOCAL, {"scene": "lab", "max_episode_steps": 800},
                 _bekris_goals),),
        ("bearing", "bearing-basic", "bearing-complementary", "warping", "oracle",
         "random"), episodes=12, seed=11,
        paper="Fig. 11: every goal reached, mean error 1.45-4.65 cm"),
    Protocol(
        "briggs-corridors", 1, "Briggs et al.: LandmarkNavigation-v0 in the corridors",
        (Setting("corridors", "homing_gym/LandmarkNavigation-v0", {"scene": "corridors"}),),
        ("selfsimilar", "oracle", "random"), episodes=6,
        place="stopped in front of the goal landmark (the task's rule: at most 1.2 m from "
              "the panel, within 30 deg of its normal, facing it)",
        paper="§5: the robot reached its goal landmarks in the building's corridors"),
    Protocol(
        "shiraishi-house", 1, "Shiraishi & Sawasaki: WorkLocations-v0 in the house, "
        "success radius 0.10 m (the env's and the paper's)",
        (Setting("house", "homing_gym/WorkLocations-v0",
                 {"scene": "house", "success_radius": 0.1}),),
        ("multires", "oracle", "random"), episodes=6,
        paper="§4: arrival within 10 cm and 2 deg of each work location"),
    Protocol(
        "local-common", 2, "one LocalHoming suite for every homing method and policy: "
        "arena, hallway, lab, house and the procedural random_rooms and random_nature, "
        "homes anywhere; ray cast, 1/120 s physics (v1: the first four scenes, TinyRenderer)",
        tuple(Setting(scene, LOCAL, {"scene": scene}, simulation=V2_SIMULATION)
              for scene in COMMON_SCENES),
        HOMING_METHODS, episodes=5),
    Protocol(
        "unseen", 2, "worlds no shipped policy was trained on: held-out procedural worlds "
        f"(random_arena, random_rooms, random_nature; seeds from {UNSEEN_SEED}), hallway, lab "
        "and house; ray cast, 1/120 s physics (v1: random_arena only, TinyRenderer)",
        (*(Setting(f"{scene} (held out)", LOCAL, {"scene": scene}, _held_out, V2_SIMULATION)
           for scene in PROCEDURAL),
         *(Setting(scene, LOCAL, {"scene": scene}, simulation=V2_SIMULATION)
           for scene in ("hallway", "lab", "house"))),
        HOMING_METHODS, episodes=5),
)}


def protocol(name: str) -> Protocol:
    """The protocol called ``name`` (``ValueError`` naming the known ones otherwise)."""
    if name not in PROTOCOLS:
        raise ValueError(f"unknown protocol {name!r}; allowed: {sorted(PROTOCOLS)}")
    return PROTOCOLS[name]
