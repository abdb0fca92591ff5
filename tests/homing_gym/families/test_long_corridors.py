"""The long_corridors family: worlds reproducible from the seed and distinct across seeds,
a floor that is long and narrow (12-30 m corridors 1.4-3 m wide, rooms and alcoves off
them) and all one reachable area, doors along the walls, walls the robot bumps into,
LocalHoming episodes in every world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.long_corridors import long_corridors_scene
from homing_gym.scenes.mesh_part import MeshPart

FORWARD = np.array([1.0, 0.0], np.float32)


def _world(seed):
    return long_corridors_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes(),
                    None if p.texture is None else p.texture.tobytes()) for p in scene.meshes)
    return scene.bounds, scene.landmarks, scene.sky_color, scene.appearance, meshes


def _grid(scene, step=0.1) -> np.ndarray:
    (xmin, ymin), (xmax, ymax) = scene.bounds
    gx, gy = np.meshgrid(np.arange(xmin + step / 2, xmax, step),
                         np.arange(ymin + step / 2, ymax, step))
    return np.stack([gx.ravel(), gy.ravel()], 1)


def _within(points, rects) -> np.ndarray:
    inside = np.zeros(len(points), bool)
    for (x0, y0), (x1, y1) in rects:
        inside |= ((points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0)
                   & (points[:, 1] <= y1))
    return inside


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(7)) == _signature(_world(7))
    worlds = [_world(seed) for seed in range(10)]
    assert len({_signature(w) for w in worlds}) == 10
    assert {w.metadata["layout"] for w in worlds} == {"I", "L", "T"}
    for w in worlds:
        assert w.name == "long_corridors" and w.fence and not w.ground_plane
        assert max(w.size) <= 30.0
        walls = next(p for p in w.meshes if p.name == "walls")
        assert walls.collision and 2.2 <= walls.vertices[:, 2].max() <= 3.0
        assert not any(p.collision for p in w.meshes
                       if p.name in ("floor", "room walls", "room floors", "leaves"))
        assert sum(len(p.faces) for p in w.meshes) + 12 * len(w.landmarks) < 4000


def test_the_generator_declares_the_solids_trimesh_would_find():
    for part in _world(3).meshes:
        if part.solid_faces and part.texture is None:      # textured boxes repeat corners
            found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
            assert sorted(map(tuple, part.solids)) == sorted(map(tuple, found)), part.name


def test_the_floor_is_long_narrow_corridors_with_rooms_all_reachable():
    doors = 0
    for seed in range(5):
        scene = _world(seed)
        corridors, rooms = scene.metadata["corridors"], scene.metadata["rooms"]
        for (x0, y0), (x1, y1) in corridors:
            length, width = max(x1 - x0, y1 - y0), min(x1 - x0, y1 - y0)
            assert 12.0 <= length <= 30.0 and 1.4 <= width <= 3.0
        points = _grid(scene)
        free = clearances(scene, points)
        floor = points[free > 0.22]
        # nearly all the floor lies in the corridors and rooms, and little of it is far
        # from a wall: a corridor's middle is at most 1.5 m from one
        assert _within(floor, corridors + rooms).mean() > 0.85
        assert np.percentile(free[free > 0.22], 95) < 1.45
        assert np.sum(_within(floor, corridors)) > 1.5 * np.sum(_within(floor, rooms))
        labels = regions(scene, 0.22, 0.05)
        assert labels.max() == 1                                    # one floor, no pockets
        (xmin, ymin), _ = scene.bounds
        for room in rooms:                                          # each joined to it
            inside = _within(points, [room]) & (free > 0.3)
            i, j = np.round((points[inside] - (xmin, ymin)) / 0.05).astype(int).T
            assert np.all(labels[i, j] == 1)
        doors += sum(lm.name == "door" for lm in scene.landmarks)
    assert doors >= 5


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=long_corridors_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "long_corridors"


def test_walls_and_furniture_block_and_leaves_and_coverings_do_not():
    scene = next(w for w in map(_world, range(10)) if any(p.name == "leaves" for p in w.meshes))
    points = _grid(scene, 0.15)
    free = clearances(scene, points)
    passable = replace(scene, meshes=tuple(
        p for p in scene.meshes if p.name not in ("floor", "room walls", "room floors", "leaves")))
    assert np.array_equal(free, clearances(passable, points))
    no_walls = replace(scene, meshes=tuple(p for p in scene.meshes if p.name != "walls"))
    assert np.any(clearances(no_walls, points) > free + 1.0)


def test_robot_bumps_into_the_corridor_walls(make_env):
    scene = _world(2)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    (x0, y0), (x1, y1) = scene.metadata["corridors"][0]
    along_x = x1 - x0 > y1 - y0
    for s in np.linspace(0.2, 0.8, 13):
        centre = np.array([x0 + s * (x1 - x0), (y0 + y1) / 2] if along_x
                          else [(x0 + x1) / 2, y0 + s * (y1 - y0)])
        heading = np.array([0.0, 1.0]) if along_x else np.array([1.0, 0.0])
        line = centre + np.linspace(0, 0.4, 9)[:, None] * heading
        if clearances(scene, line).min() > 0.25:
            break
    else:
        raise AssertionError("no clear line to a wall")
    a = math.atan2(heading[1], heading[0])
    env.reset(seed=0, options={"start": (*centre, a)})
    collided = False
    for _ in range(60):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    assert collided
    assert _within(np.array([info["pose"][:2]]), scene.metadata["corridors"])[0]
