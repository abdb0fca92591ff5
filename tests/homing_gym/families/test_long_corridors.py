"""The long_corridors family: a floor that is long and narrow (12-30 m corridors 1.4-3 m
wide, rooms and alcoves off them) and all one reachable area, doors along the walls,
walls the robot bumps into."""

import math

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes.base import clearances

FAMILY = "long_corridors"
PASSABLE = ("floor", "room walls", "room floors", "leaves")


def _within(points, rects) -> np.ndarray:
    inside = np.zeros(len(points), bool)
    for (x0, y0), (x1, y1) in rects:
        inside |= ((points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0)
                   & (points[:, 1] <= y1))
    return inside


def test_worlds_are_i_l_and_t_layouts_of_solid_walls_cheap_to_cast(world):
    worlds = [world(seed) for seed in range(10)]
    assert {w.metadata["layout"] for w in worlds} == {"I", "L", "T"}
    for w in worlds:
        assert w.name == "long_corridors" and w.fence and not w.ground_plane
        assert max(w.size) <= 30.0
        walls = next(p for p in w.meshes if p.name == "walls")
        assert walls.collision and 2.2 <= walls.vertices[:, 2].max() <= 3.0
        assert not any(p.collision for p in w.meshes if p.name in PASSABLE)
        assert sum(len(p.faces) for p in w.meshes) + 12 * len(w.landmarks) < 4000


def test_the_generator_declares_the_solids_trimesh_would_find(world,
                                                              assert_solids_as_trimesh_finds):
    assert_solids_as_trimesh_finds(p for p in world(3).meshes   # textured boxes repeat corners
                                   if p.solid_faces and p.texture is None)


def test_the_floor_is_long_narrow_corridors_with_rooms_all_reachable(world, floor_grid):
    doors = 0
    for seed in range(5):
        scene = world(seed)
        corridors, rooms = scene.metadata["corridors"], scene.metadata["rooms"]
        for (x0, y0), (x1, y1) in corridors:
            length, width = max(x1 - x0, y1 - y0), min(x1 - x0, y1 - y0)
            assert 12.0 <= length <= 30.0 and 1.4 <= width <= 3.0
        points = floor_grid(scene)
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


def test_walls_and_furniture_block_and_leaves_and_coverings_do_not(world, floor_grid,
                                                                   without):
    scene = next(w for w in map(world, range(10)) if any(p.name == "leaves" for p in w.meshes))
    points = floor_grid(scene, 0.15)
    free = clearances(scene, points)
    assert np.array_equal(free, clearances(without(scene, *PASSABLE), points))
    assert np.any(clearances(without(scene, "walls"), points) > free + 1.0)


def test_robot_bumps_into_the_corridor_walls(world, drive):
    scene = world(2)
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
    collided, pose = drive(scene, (*centre, math.atan2(heading[1], heading[0])), 60)
    assert collided
    assert _within(np.array([pose[:2]]), scene.metadata["corridors"])[0]
