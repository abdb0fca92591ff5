"""World families: procedural generators of unlimited seeded worlds, each family a kind of
place users bring (indoor, built outdoor, natural, few-landmark arenas), each world with
its own appearance (:func:`~homing_gym.scenes.appearance.random_appearance`: sky and its
gradient, light, shadows, camera height) on top of its own layout.

Every family is a scene name (``gym.make(..., scene="forest")``): a seeded reset draws a
new world from the seed. :data:`FAMILIES` says what each family is for in the
generalisation study (``docs/generalisation.md``): ``train`` families are the ones a
shipped recipe may train on, ``validation`` families (and the third-party worlds of
``../shared/worlds``) the ones recipes and checkpoints are chosen on, and ``test``
families the ones the ``unseen-families`` protocol measures, which no recipe trains or
selects on.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import import_module
from typing import Callable

import numpy as np

from homing_gym.scenes.base import Scene

KINDS = ("indoor", "built", "natural", "arena")
ROLES = ("train", "validation", "test")


@dataclass(frozen=True)
class Family:
    """A world family: its scene ``name``, its ``kind`` (:data:`KINDS`), its ``role`` in
    the generalisation study (:data:`ROLES`) and a one-line ``description``; ``module``
    is the module of ``homing_gym.scenes`` whose ``<scene>_scene(rng)`` draws a world."""

    name: str
    kind: str
    role: str
    description: str
    module: str

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"family {self.name!r}: unknown kind {self.kind!r}; allowed: {KINDS}")
        if self.role not in ROLES:
            raise ValueError(f"family {self.name!r}: unknown role {self.role!r}; allowed: {ROLES}")

    @property
    def build(self) -> Callable[[np.random.Generator], Scene]:
        """The family's world generator, ``build(rng) -> Scene``."""
        return getattr(import_module(f"homing_gym.scenes.{self.module}"), f"{self.name}_scene")


FAMILIES: dict[str, Family] = {f.name: f for f in (
    Family("random_rooms", "indoor", "train",
           "1-6 rooms with doors, furniture, plants, pictures", "random_rooms"),
    Family("random_nature", "natural", "train",
           "open ground, trees, rocks, bushes, distant hills", "random_nature"),
    Family("random_arena", "arena", "train",
           "2.4 m walled square, 3-8 landmarks", "random_arena"),
    Family("offices", "indoor", "train",
           "open-plan office: desks in rows, partitions, cabinets, windows", "families.offices"),
    Family("forest", "natural", "train",
           "dense trunks of many sizes, leaf litter, undergrowth", "families.forest"),
    Family("desert", "natural", "train",
           "sparse scrub on sand, far mesas and dunes on the horizon", "families.desert"),
    Family("labs", "indoor", "validation",
           "cluttered lab: benches, shelves, boxes and carts in one hall", "families.labs"),
    Family("rocky", "natural", "validation",
           "boulders and outcrops on gravel, ridges on the horizon", "families.rocky"),
    Family("grassland", "natural", "test",
           "open grass: dense thin blades near the camera, the robot drives through "
           "them; a few shrubs and far trees", "families.grassland"),
    Family("streets", "built", "test",
           "a street or plaza between building blocks with windows, posts, benches",
           "families.streets"),
    Family("long_corridors", "indoor", "test",
           "long corridors with doors, alcoves, junctions and notice boards",
           "families.long_corridors"),
)}


def family(name: str) -> Family:
    """The family called ``name`` (``ValueError`` naming the known ones otherwise)."""
    if name not in FAMILIES:
        raise ValueError(f"unknown world family {name!r}; allowed: {sorted(FAMILIES)}")
    return FAMILIES[name]


def families_in(role: str) -> tuple[str, ...]:
    """The names of the families with ``role`` (:data:`ROLES`)."""
    if role not in ROLES:
        raise ValueError(f"unknown role {role!r}; allowed: {ROLES}")
    return tuple(name for name, f in FAMILIES.items() if f.role == role)
