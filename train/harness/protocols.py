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

Each paper protocol carries the paper's claims (:class:`Claim`): what the paper reports for
one of our methods, its numbers as printed, where (section, figure, table), and how our
setting differs from the paper's; the matrix sets them beside our cells.

``homing-eval --protocol NAME --policy METHOD`` runs one method on a protocol (``--seed
S``: on another draw of its episodes, recorded as not the canonical one);
``homing-suite --protocols ...`` runs every applicable method on each and writes the
methods x protocols matrix. Changing what a protocol does means a new ``version``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Callable, Sequence

import numpy as np

from homing_gym.scenes import scene_factory
from homing_gym.scenes.families import families_in
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
class Claim:
    """What a paper reports for the method ``method`` (ours) in the setting a protocol
    reproduces: ``text`` (quoted where in quotes), ``numbers`` as the paper prints them
    ("" where it prints none), ``where`` (paper, section, figure or table), ``runs`` =
    (runs that reached the goal, runs) where the paper's own figures give them, and
    ``differs``: how our protocol differs from the paper's setting."""

    method: str
    text: str
    numbers: str
    where: str
    differs: str
    runs: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        if self.runs is not None and not 0 <= self.runs[0] <= self.runs[1] >= 1:
            raise ValueError(f"runs must be (reached, runs) with 0 <= reached <= runs >= 1, "
                             f"got {self.runs}")


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
    claims: tuple[Claim, ...] = ()     # the paper's, beside our numbers
    privileged: str = ""               # anything beyond pixels the protocol gives
    place: str = ""                    # a place rule other than the radius (the task's)
    canonical_seed: int | None = None  # set by reseeded(): the protocol's own seed
    #: Env ids whose shipped policies act here besides policies of the settings' own env
    #: ids (a LocalHoming policy homes to a route's targets one by one).
    policy_envs: tuple[str, ...] = ()
    #: Why no shipped policy can act in this protocol ("" where one can); the matrix
    #: says it in the policies' rows instead of leaving them blank.
    no_policy: str = ""

    @property
    def canonical(self) -> bool:
        """Whether the episodes are the protocol's own draw (not :meth:`reseeded`)."""
        return self.canonical_seed in (None, self.seed)

    def reseeded(self, seed: int) -> "Protocol":
        """The protocol with its episodes drawn from base seed ``seed`` (``homing-eval
        --protocol NAME --seed S``): the same settings, other scenes, homes and starts;
        not the canonical draw unless ``seed`` is the protocol's own."""
        own = self.seed if self.canonical_seed is None else self.canonical_seed
        return replace(self, seed=seed, canonical_seed=own)

    @property
    def label(self) -> str:
        name = f"{self.name} v{self.version}"
        return name if self.canonical else (f"{name} (seed {self.seed}: not the canonical "
                                            f"draw, seed {self.canonical_seed})")

    def success_radius(self, setting: Setting) -> float:
        return float(setting.env_kwargs.get("success_radius", SUCCESS_RADIUS))

    def command(self, method: str, episodes: int | None = None) -> str:
        """The ``homing-eval`` command that reproduces one matrix cell."""
        extra = f" --episodes {episodes}" if episodes not in (None, self.episodes) else ""
        extra += "" if self.canonical else f" --seed {self.seed}"
        return f"homing-eval --protocol {self.name} --policy {method}{extra} --out OUT.json"


def episodes_key(protocol: Protocol, setting: Setting) -> tuple:
    """Equal for two settings, of one protocol or two, that run the same episodes: the
    same env id and env kwargs, the same episode draw and the same seed (``unseen`` v2's
    hallway, lab and house were ``local-common``'s)."""
    return (setting.env_id, json.dumps(setting.kwargs(), sort_keys=True), setting.tasks,
            protocol.seed)


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
ROUTE = "homing_gym/RouteFollowing-v0"
#: Every classical method that runs LocalHoming from pixels alone, and the policies.
HOMING_METHODS = ("oracle", "random", "snapshot", "warping", "min-warping", "distance", "alv",
                  "did", POLICIES)
#: Held out from every shipped policy's training: seeds of the procedural worlds far from
#: the training seeds, and scenes it never saw.
UNSEEN_SEED = 10_000_000
#: ``local-common``'s seeds (v3): clear of every training seed (a training env ``i``
#: starts in the world of seed ``seed + i``) and of ``unseen``'s.
COMMON_SEED = 20_000_000
#: ``unseen-families``' seeds: the test families are held out whole, so any seed would
#: do; these are clear of every other protocol's.
FAMILIES_SEED = 30_000_000
#: ``validation-families``' seeds.
VALIDATION_SEED = 40_000_000
#: ``train-families``' seeds: far beyond any training env's worlds (a training env ``i``
#: draws worlds from seed ``seed + i`` on).
TRAIN_FAMILIES_SEED = 50_000_000
#: ``routes``' seeds: clear of every training seed and of every other protocol's.
ROUTES_SEED = 60_000_000
#: Every method that follows a route from pixels alone, and the policies.
ROUTE_METHODS = ("oracle", "random", "snapshot", "warping", "min-warping", "did",
                 "perfect-memory", "infomax", POLICIES)
#: The worlds of ``local-common`` v2: the paper scenes and the procedural worlds.
COMMON_SCENES = ("arena", "hallway", "lab", "house", "random_rooms", "random_nature")
PROCEDURAL = ("random_arena", "random_rooms", "random_nature")


def _held_out(episodes: int, seed: int) -> list[Task]:
    """Seeds from :data:`UNSEEN_SEED` on: procedural worlds no policy trained on, and
    homes and starts that no other protocol draws."""
    return [(UNSEEN_SEED + seed + i, None, None) for i in range(episodes)]


def _family_seeds(k: int, episodes: int, seed: int, first_seed: int = 0) -> list[Task]:
    """Seeds from ``first_seed`` (default :data:`FAMILIES_SEED`) on for a protocol's
    ``k``-th family, a million apart from the next family's (the same seed draws the same
    sky, light and camera height in every family: each family gets its own)."""
    first = (first_seed or FAMILIES_SEED) + 1_000_000 * k + seed
    return [(first + i, None, None) for i in range(episodes)]


def _family_settings(role: str, first_seed: int = 0) -> tuple[Setting, ...]:
    """One LocalHoming setting per family of ``role`` (homes anywhere, starts 0.3-2.0 m,
    ray cast), the ``k``-th drawing its seeds from ``first_seed`` (:func:`_family_seeds`)."""
    return tuple(Setting(name, LOCAL, {"scene": name, "start_distance": [0.3, 2.0]},
                         partial(_family_seeds, k, first_seed=first_seed), V2_SIMULATION)
                 for k, name in enumerate(families_in(role)))


def _route_seeds(k: int, episodes: int, seed: int) -> list[Task]:
    """Seeds from :data:`ROUTES_SEED` on for ``routes``' ``k``-th setting, a million
    apart from the next setting's."""
    first = ROUTES_SEED + 1_000_000 * k + seed
    return [(first + i, None, None) for i in range(episodes)]


def _common(episodes: int, seed: int) -> list[Task]:
    """Seeds from :data:`COMMON_SEED` on: no training run starts in these worlds."""
    return [(COMMON_SEED + seed + i, None, None) for i in range(episodes)]

PROTOCOLS: dict[str, Protocol] = {p.name: p for p in (
    Protocol(
        "hong1991", 1, "Hong et al.: the hallway, a synchro-drive robot (it translates "
        "without turning), starts 1 ft (0.3048 m) from a random home with the home's "
        "heading; panorama 60 x 360 (1 deg per column)",
        (Setting("hallway, 1 ft", LOCAL,
                 {"scene": "hallway", "drive": "synchro", "panorama_shape": [60, 360],
                  "max_episode_steps": 200}, _hong_one_foot),),
        ("snapshot", "warping", "oracle", "random"), episodes=10,
        no_policy="the synchro drive translates without turning, and every shipped "
                  "policy acts by turning and stepping",
        claims=(Claim(
            "snapshot", "17 hallway images taken at targets about 1 ft apart; the robot, "
            "placed 1 ft from the first, homed to each in sequence and \"was able to traverse "
            "this path successfully and reach the final target location\"",
            "17 targets, about 1 ft apart; start 1 ft from the first; no error figures",
            "Hong et al. 1991, §5",
            "the paper: one route on a real robot, consecutive homings (an error carries to "
            "the next), no success radius stated; ours: independent homings to random homes "
            "in our hallway model, 1 ft away, stopped within 0.15 m",
            runs=(17, 17)),)),
    Protocol(
        "yukim", 1, "Yu & Kim: the arena, the nest among the four landmarks, starts "
        "0.3-1.4 m away in the four distance bins of Fig. 6, random headings",
        (Setting("arena, nest", LOCAL, {"scene": "arena", "max_episode_steps": 300},
                 _yukim_nest),),
        ("distance", "warping", "snapshot", "oracle", "random", POLICIES), episodes=12,
        claims=tuple(Claim(
            method, text, "100 trials per start distance, in simulation, no reference "
            "compass; the rates are plotted, not printed", "Yu & Kim, §III, Fig. 6",
            "the paper: its own simulator of the 240 cm arena, success criterion not "
            "stated; ours: rendered panoramas of our arena model in closed loop, 3 episodes "
            "per distance bin (0.3-1.4 m), 300 steps, stopped within 0.15 m")
            for method, text in (
                ("distance", "distance estimation \"shows constantly high probability of "
                             "returning to the nest\", \"regardless of the distance\""),
                ("warping", "the pixel-based image matching of Franz et al. \"declines "
                            "rapidly as the mobile agent gets farther from the nest\"")))),
    Protocol(
        "yukim-anywhere", 1, "the arena with homes anywhere (not the paper's setting: "
        "most homes lie outside the landmarks' quadrilateral)",
        (Setting("arena, anywhere", LOCAL, {"scene": "arena"}),),
        HOMING_METHODS, episodes=10),
    Protocol(
        "bekris-lab", 1, "Bekris et al.: the lab, goals A-F, random starts 0.5-3 m away "
        "(Fig. 11)",
        (Setting("lab, A-F", LOCAL, {"scene": "lab", "max_episode_steps": 800},
                 _bekris_goals),),
        ("bearing", "bearing-basic", "bearing-complementary", "warping", "oracle",
         "random", POLICIES), episodes=12, seed=11,
        claims=(
            Claim("bearing", "the unified law, run 30 times to each of the 6 marked "
                  "positions (180 runs): accuracy \"in the order of a very few centimeters "
                  "for all goal positions\"; no failure reported",
                  "mean error A 1.45, B 4.65, C 2.85, D 2.55, E 3.22, F 2.28 cm; "
                  "s.d. 1.13-2.10 cm", "Bekris et al., §5, Fig. 11",
                  "the paper: a real robot tracking three coloured posters, its starts "
                  "not given; ours: the lab model, 2 random starts per goal 0.5-3 m away, "
                  "stopped within 0.15 m (the paper's figure is the final error)",
                  runs=(180, 180)),
            *(Claim(method, text, numbers, "Bekris et al., §5, Fig. 10",
                    "Fig. 10: goals A, C and E only, 3 starts in each of 3 start regions; "
                    "ours: goals A-F, 2 random starts per goal, so the share of goals "
                    "outside the law's reachability set differs; stopped within 0.15 m",
                    runs=runs)
              for method, text, numbers, runs in (
                  ("bearing-basic", "the basic law \"fails to reach certain goal positions, "
                   "independently of the starting position\": E from every start",
                   "A and C reached from all 9 starts (0.0-11.5 cm), E: Fail in all 9",
                   (18, 27)),
                  ("bearing-complementary", "the complementary law \"fails to reach "
                   "certain goal positions, independently of the starting position\": A "
                   "and C from every start",
                   "E reached from all 9 starts (2.5-9.0 cm), A and C: Fail in all 9",
                   (9, 27)))))),
    Protocol(
        "briggs-corridors", 1, "Briggs et al.: LandmarkNavigation-v0 in the corridors",
        (Setting("corridors", "homing_gym/LandmarkNavigation-v0", {"scene": "corridors"}),),
        ("selfsimilar", "oracle", "random"), episodes=6,
        no_policy="no shipped policy was trained on LandmarkNavigation-v0, whose goal is "
                  "a landmark's panel image",
        place="stopped in front of the goal landmark (the task's rule: at most 1.2 m from "
              "the panel, within 30 deg of its normal, facing it)",
        claims=(Claim(
            "selfsimilar", "a navigation system \"reliable and robust with respect to "
            "landmark orientation, varying lighting conditions, and distances to the "
            "landmarks\"; navigation plans routes over the landmark visibility graph (§4.2, "
            "§4.3)", "", "Briggs et al. 2000, §5",
            "the paper reports no navigation runs, success rate or error; ours: "
            "LandmarkNavigation-v0 in our corridors, the task's place rule"),)),
    Protocol(
        "shiraishi-house", 1, "Shiraishi & Sawasaki: WorkLocations-v0 in the house, "
        "success radius 0.10 m (the env's and the paper's)",
        (Setting("house", "homing_gym/WorkLocations-v0",
                 {"scene": "house", "success_radius": 0.1}),),
        ("multires", "oracle", "random"), episodes=6,
        no_policy="no shipped policy was trained on WorkLocations-v0, whose goal is a "
                  "taught location's index",
        claims=(Claim(
            "multires", "\"arrival at the goal was generally recognized with an accuracy "
            "of 10 centimeters or better\" (§4 (1)); self-localisation at a work location "
            "(§4 (2-2), Fig. 10): location error \"less than 10 centimeters\", direction "
            "error \"less than 2 degrees\"",
            "arrival <= 10 cm (\"generally\"); location < 10 cm and direction < 2 deg, "
            "measured within 50 cm of where the points were taught; no run counts",
            "Shiraishi & Sawasaki, §4 (1), §4 (2-2), Fig. 10",
            "the paper: arrival on a dolly pushed by hand along the displayed deviation, "
            "localisation on an HRP robot; ours: WorkLocations-v0 in our house model in "
            "closed loop, stopped within 0.10 m"),)),
    Protocol(
        "local-common", 3, "one LocalHoming suite for every homing method and policy: "
        "arena, hallway, lab, house and the procedural random_rooms and random_nature, "
        f"homes anywhere, seeds from {COMMON_SEED}; ray cast, 1/120 s physics (v2: seeds "
        "from 0, whose first procedural worlds were the first worlds of the training "
        "envs; v1: the first four scenes, TinyRenderer)",
        tuple(Setting(scene, LOCAL, {"scene": scene}, _common, V2_SIMULATION)
              for scene in COMMON_SCENES),
        HOMING_METHODS, episodes=5),
    Protocol(
        "unseen", 3, "worlds no shipped policy was trained on: held-out procedural worlds "
        f"(random_arena, random_rooms, random_nature) and the hallway, lab and house, all "
        f"with seeds from {UNSEEN_SEED} (homes and starts unlike local-common's); ray cast, "
        "1/120 s physics (v2: the hallway, lab and house ran local-common's episodes; v1: "
        "random_arena only, TinyRenderer)",
        tuple(Setting(f"{scene} (held out)", LOCAL, {"scene": scene}, _held_out, V2_SIMULATION)
              for scene in (*PROCEDURAL, "hallway", "lab", "house")),
        HOMING_METHODS, episodes=5),
    Protocol(
        "unseen-families", 1, "whole world families that no shipped policy or recipe "
        "trains or selects on (:data:`~homing_gym.scenes.families.FAMILIES`, role "
        f"'test'): {', '.join(families_in('test'))}, one setting each (weighted equally), "
        "every world with its own sky, light, shadows and camera height (0.02-0.5 m); "
        f"homes anywhere, starts 0.3-2.0 m, seeds from {FAMILIES_SEED} (a million apart per "
        "family); ray cast, 1/120 s "
        "physics",
        _family_settings("test"), HOMING_METHODS, episodes=100),
    Protocol(
        "validation-families", 1, "the validation families (:data:`~homing_gym.scenes."
        f"families.FAMILIES`, role 'validation'): {', '.join(families_in('validation'))}, "
        "for choosing recipes and checkpoints (never the test families); otherwise as "
        f"unseen-families, seeds from {VALIDATION_SEED}",
        _family_settings("validation", VALIDATION_SEED), HOMING_METHODS, episodes=50),
    Protocol(
        "train-families", 1, "the training families (:data:`~homing_gym.scenes.families."
        f"FAMILIES`, role 'train'): {', '.join(families_in('train'))}, on worlds no "
        f"training run draws (seeds from {TRAIN_FAMILIES_SEED}): how a method does where "
        "the policies learnt, beside the validation and test families; otherwise as "
        "unseen-families",
        _family_settings("train", TRAIN_FAMILIES_SEED), HOMING_METHODS, episodes=50),
    Protocol(
        "routes", 1, "RouteFollowing-v0 under the stop rule: Hong et al.'s 17 targets "
        "1 ft apart in the hallway, and curved routes (route='random': 17 legs of 1 ft, "
        "each turning by up to 30 degrees) drawn per episode in held-out worlds of "
        "random_nature and random_rooms; success = stopped within 0.15 m of the last "
        f"target after leaving every earlier one; seeds from {ROUTES_SEED}; ray cast, "
        "1/120 s physics; LocalHoming policies home to the targets one by one",
        (Setting("hallway, Hong's route", ROUTE,
                 {"scene": "hallway", "success_radius": SUCCESS_RADIUS},
                 partial(_route_seeds, 0), V2_SIMULATION),
         *(Setting(f"{scene}, curved", ROUTE,
                   {"scene": scene, "route": "random", "success_radius": SUCCESS_RADIUS},
                   partial(_route_seeds, k), V2_SIMULATION)
           for k, scene in enumerate(("random_nature", "random_rooms"), start=1))),
        ROUTE_METHODS, episodes=10, policy_envs=(LOCAL,),
        claims=(
            Claim("snapshot", "17 hallway images taken at targets about 1 ft apart; the "
                  "robot, placed 1 ft from the first, homed to each in sequence and \"was "
                  "able to traverse this path successfully and reach the final target "
                  "location\"", "one route of 17 targets, no error figures",
                  "Hong et al. 1991, §5",
                  "the paper: one run on a real synchro-drive robot, no success radius "
                  "stated; ours: our differential-drive robot, the last stop within "
                  "0.15 m, the cell over all three settings of which the hallway is the "
                  "paper's (per setting: docs/routes.md)", runs=(1, 1)),
            *(Claim(method, "route navigation as \"a search for familiar views\" with \"a "
                    "simple scanning routine\", tested \"by learning a series of routes "
                    "through visually cluttered environments\": \"not only is the approach "
                    "successful\", the routes learnt resemble desert ants'", "",
                    "Baddeley et al. 2012, abstract",
                    "the paper: an ant-sized agent in worlds of objects seen as silhouettes "
                    "against the sky, judged on staying on the route (no stop, no targets); "
                    "ours: textured procedural worlds and the hallway, a robot that must "
                    "stop within 0.15 m of each target")
              for method in ("perfect-memory", "infomax")))),
)}


def protocol(name: str) -> Protocol:
    """The protocol called ``name`` (``ValueError`` naming the known ones otherwise)."""
    if name not in PROTOCOLS:
        raise ValueError(f"unknown protocol {name!r}; allowed: {sorted(PROTOCOLS)}")
    return PROTOCOLS[name]
