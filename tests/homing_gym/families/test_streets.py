"""The streets family: a street or a plaza lined by building blocks with windowed facades
and a skyline beyond, little sky between 10 and 25 degrees up, furniture the robot bumps
into and flat marks it drives over."""

import math

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.streets import REACH

FAMILY = "streets"
PASSABLE = {"ground", "road", "marks", "crowns", "water"}


def _buildings(scene) -> np.ndarray:
    """Each building block as (xmin, ymin, xmax, ymax, height), metres."""
    blocks = []
    for part in scene.meshes:
        if part.name.startswith("buildings"):
            for faces in part.solids:
                corners = part.vertices[np.unique(part.faces[faces])]
                blocks.append((*corners[:, :2].min(axis=0), *corners[:, :2].max(axis=0),
                               corners[:, 2].max()))
    return np.array(blocks)


def _lined(blocks: np.ndarray, scene) -> list[float]:
    """The share of each side of the free floor (x = xmin, x = xmax, y = ymin, y = ymax)
    along which a facade stands flush."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    shares = []
    for axis, line, lo, hi in ((0, xmin, ymin, ymax), (0, xmax, ymin, ymax),
                               (1, ymin, xmin, xmax), (1, ymax, xmin, xmax)):
        flush = blocks[np.isclose(blocks[:, axis], line) | np.isclose(blocks[:, axis + 2], line)]
        s = np.linspace(lo, hi, 200)
        along = 1 - axis
        covered = ((s[:, None] >= flush[None, :, along]) & (s[:, None] <= flush[None, :, along + 2]))
        shares.append(covered.any(axis=1).mean() if len(flush) else 0.0)
    return shares


def test_worlds_are_streets_and_plazas_of_fenced_floor_cheap_to_cast(world):
    worlds = [world(seed) for seed in range(8)]
    assert {w.metadata["layout"] for w in worlds} == {"street", "plaza"}
    for w in worlds:
        assert w.name == "streets" and w.fence and not w.ground_plane and not w.walls
        width, depth = w.size
        assert 6.0 <= width <= 12.0 and 8.0 <= depth <= 20.0
        assert {p.name for p in w.meshes if not p.collision} <= PASSABLE
        assert sum(len(p.faces) for p in w.meshes) < 4000          # cheap to cast


def test_the_generator_declares_the_solids_trimesh_would_find(world,
                                                              assert_solids_as_trimesh_finds):
    assert_solids_as_trimesh_finds(p for p in world(2).meshes if p.solid_faces)


def test_blocks_line_the_floor_with_windowed_facades_and_a_skyline_beyond(world):
    for seed in range(10):
        scene = world(seed)
        blocks = _buildings(scene)
        (xmin, ymin), (xmax, ymax) = scene.bounds
        shares = _lined(blocks, scene)
        if scene.metadata["layout"] == "street":                 # both long sides lined
            assert min(shares[:2]) > 0.5, (seed, shares)
        else:                                                    # a plaza: all round
            assert sum(s > 0.4 for s in shares) >= 3, (seed, shares)
        inside = ((blocks[:, 0] < xmax - 1e-6) & (blocks[:, 2] > xmin + 1e-6)
                  & (blocks[:, 1] < ymax - 1e-6) & (blocks[:, 3] > ymin + 1e-6))
        assert not inside.any()                                  # none on the free floor
        assert 5.5 <= blocks[:, 4].min() and blocks[:, 4].max() <= 31.0
        corners = np.hypot(blocks[:, [0, 2]][:, :, None], blocks[:, [1, 3]][:, None, :])
        assert corners.max() <= REACH + 1e-6                     # on the ground's disc
        near = np.hypot(np.maximum(0, np.maximum(blocks[:, 0], -blocks[:, 2])),
                        np.maximum(0, np.maximum(blocks[:, 1], -blocks[:, 3])))
        assert np.sum(near > 14.0) >= 3                          # a far skyline
        for part in scene.meshes:
            if part.name.startswith("buildings"):
                light = part.texture.mean(axis=2)
                panes = light < 0.7 * np.median(light)           # windows darker than walls
                assert 0.05 < panes.mean() < 0.7
        assert regions(scene, 0.22, 0.05).max() == 1             # one floor, no pockets


def test_little_sky_shows_between_the_blocks(world, sky_seen):
    """With a magenta sky, little of it shows 10-25 degrees above the horizon, where
    random_nature shows mostly sky."""
    assert max(sky_seen(world(seed), seed)[4:16].mean() for seed in range(3)) < 0.3
    assert sky_seen(world(0, "random_nature"), 0)[4:16].mean() > 0.5


def test_only_furniture_and_buildings_block_the_robot(world, floor_grid, without):
    scene = world(0)
    grid = floor_grid(scene, shape=(50, 80))
    free = clearances(scene, grid)
    assert np.array_equal(free, clearances(without(scene, *PASSABLE), grid))
    opened = clearances(without(scene, "furniture"), grid)
    assert np.all(opened >= free) and np.any(opened > free + 0.3)


def test_robot_bumps_into_furniture_and_drives_over_road_marks(world, part, drive,
                                                               line_through):
    scene = world(0)
    furniture = part(scene, "furniture")
    bumped = 0
    for faces in furniture.solids[:12]:
        corners = furniture.vertices[np.unique(furniture.faces[faces])]
        if corners[:, 2].min() > 0.01:
            continue                                       # a lamp head, a backrest
        centre = (corners[:, :2].min(axis=0) + corners[:, :2].max(axis=0)) / 2
        reach = np.abs(corners[:, :2] - centre).max()
        for a in np.linspace(0, 2 * math.pi, 16, endpoint=False):
            heading = np.array([math.cos(a), math.sin(a)])
            start = centre - (reach + 0.5) * heading
            line = start + np.linspace(0, 0.25, 6)[:, None] * heading
            if clearances(scene, line).min() > 0.22:
                collided, pose = drive(scene, (*start, a), 40)
                assert collided and np.abs(pose[:2] - centre).max() > 0.1
                bumped += 1
                break
        if bumped == 2:
            break
    assert bumped == 2
    marks = part(scene, "marks").triangles        # a clear 1.4 m line across a mark
    start = line_through(scene, marks[::5, 0, :2], length=1.4, turn=0.3, what="a mark")
    collided, pose = drive(scene, start, 35)
    assert not collided and math.dist(pose[:2], start[:2]) > 0.9
