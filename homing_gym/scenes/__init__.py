"""Scenes: declarative worlds and the registry that names them.

A scene name maps to a :class:`SceneFactory`. Fixed scenes return the same
:class:`Scene` every episode; randomised scenes draw a new one from the episode's random
generator. Add a scene with :func:`register_scene`; the env core needs no change.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from homing_gym.scenes.arena import arena_scene
from homing_gym.scenes.base import SHAPES, Landmark, Scene, Wall, square_walls
from homing_gym.scenes.corridors import corridors_scene
from homing_gym.scenes.families import FAMILIES
from homing_gym.scenes.hallway import hallway_scene
from homing_gym.scenes.house import house_scene
from homing_gym.scenes.lab import lab_scene
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.mesh_scene import MeshScene, mesh_scene_from_spec
from homing_gym.scenes.random_arena import random_arena_scene
from homing_gym.scenes.random_nature import random_nature_scene
from homing_gym.scenes.random_rooms import random_rooms_scene


@dataclass(frozen=True)
class SceneFactory:
    """How to obtain a scene: ``build(rng)`` returns it; ``randomised`` says whether it
    changes from episode to episode (then ``build`` is called at every reset)."""

    build: Callable[[np.random.Generator], Scene]
    randomised: bool = False
    description: str = ""


_SCENES: dict[str, SceneFactory] = {}
#: A scene string starting with this names a mesh file.
MESH_PREFIX = "mesh:"


def register_scene(name: str, factory: SceneFactory) -> None:
    """Make ``name`` usable as ``gym.make(..., scene=name)``."""
    _SCENES[name] = factory


def available_scenes() -> list[str]:
    """Names of the registered scenes."""
    return sorted(_SCENES)


def scene_factory(scene: "str | Scene | SceneFactory") -> SceneFactory:
    """The factory for a scene name or a ``"mesh:PATH"`` string
    (:mod:`homing_gym.scenes.mesh_scene`), or a fixed factory around a :class:`Scene`
    object (a :class:`SceneFactory` is returned as is)."""
    if isinstance(scene, SceneFactory):
        return scene
    if isinstance(scene, Scene):
        return SceneFactory(build=lambda rng, s=scene: s, description=scene.name)
    if isinstance(scene, str) and scene.startswith(MESH_PREFIX):
        return scene_factory(mesh_scene_from_spec(scene))
    if not isinstance(scene, str) or scene not in _SCENES:
        raise ValueError(f"unknown scene {scene!r}; allowed: {available_scenes()}, "
                         f"'{MESH_PREFIX}PATH' for a mesh file, a Scene or a SceneFactory "
                         f"(a list of names is for homing-train: env k of its vector env "
                         f"builds name k mod n); a scene your module registers needs "
                         f"--import MODULE on the command line")
    return _SCENES[scene]


register_scene("arena", SceneFactory(
    build=lambda rng: arena_scene(),
    description="Yu & Kim arena: 2.4 m square, four red cylinders"))
register_scene("corridors", SceneFactory(
    build=lambda rng: corridors_scene(),
    description="8 x 6 m: four rooms off a corridor, 14 barcoded self-similar landmarks "
                "(Briggs et al. 2000)"))
register_scene("hallway", SceneFactory(
    build=lambda rng: hallway_scene(),
    description="Hong et al. 1991 corridor: 8 x 1.8 m, doors, posters, lamps; has a route"))
register_scene("house", SceneFactory(
    build=lambda rng: house_scene(),
    description="8 x 6 m home: living room, kitchen, bedroom, furniture, pictures; "
                "work locations and travel paths (Shiraishi & Sawasaki)"))
register_scene("lab", SceneFactory(
    build=lambda rng: lab_scene(),
    description="Bekris et al. Fig. 9 lab: 6 x 5 m, three coloured poster columns, "
                "door, desk, boxes; marked positions A-F"))
register_scene("random_arena", SceneFactory(
    build=random_arena_scene, randomised=True,
    description="2.4 m square, 3-8 random landmarks and textures per episode"))
register_scene("random_rooms", SceneFactory(
    build=random_rooms_scene, randomised=True,
    description="procedural indoor world per episode: 1-6 rooms with doors, furniture, "
                "plants, pictures, random textures"))
register_scene("random_nature", SceneFactory(
    build=random_nature_scene, randomised=True,
    description="procedural outdoor world per episode: open ground, trees, rocks, bushes, "
                "distant hills, fenced 6-10 m square"))

for _family in FAMILIES.values():          # the world families not registered above
    if _family.name not in _SCENES:
        register_scene(_family.name, SceneFactory(
            build=lambda rng, f=_family: f.build(rng), randomised=True,
            description=f"world family ({_family.kind}): {_family.description}"))

__all__ = ["MESH_PREFIX", "SHAPES", "Landmark", "MeshPart", "MeshScene", "Scene",
           "SceneFactory", "Wall", "available_scenes", "register_scene", "scene_factory",
           "square_walls"]
