"""The grassland family: dense thin grass that fills an ant's-eye view and that the robot
drives through, shrubs and rocks it bumps into, one open floor."""

import math

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.grassland import BLADES

FAMILY = "grassland"


def test_worlds_are_fenced_squares_each_with_its_own_amount_of_grass(world, part):
    worlds = [world(seed) for seed in range(6)]
    assert len({len(part(w, "grass").faces) for w in worlds}) == 6
    for w in worlds:
        assert w.name == "grassland" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 8.0


def test_grass_is_dense_thin_and_does_not_block(world, part, without):
    for seed in range(3):
        scene = world(seed)
        grass = part(scene, "grass")
        assert not grass.collision and 0.9 * BLADES[0] <= len(grass.faces) <= BLADES[1]
        corners = grass.triangles
        height = corners[:, 2, 2]
        width = np.linalg.norm(corners[:, 1, :2] - corners[:, 0, :2], axis=1)
        assert 0.05 <= height.min() and height.max() <= 0.6 + 1e-9
        assert width.max() <= 0.12 + 1e-9 and np.median(width / height) < 0.5   # thin
        feet = corners[:, 0, :2]
        (xmin, ymin), (xmax, ymax) = scene.bounds
        inside = np.all((feet > (xmin, ymin)) & (feet < (xmax, ymax)), axis=1)
        assert inside.sum() / (scene.size[0] * scene.size[1]) > 70      # blades a m^2
        assert np.array_equal(clearances(scene, feet), clearances(without(scene, "grass"), feet))


def test_the_floor_is_one_open_area(world):
    for seed in range(5):
        assert regions(world(seed), 0.22, 0.05).max() == 1              # no pockets


def test_an_ants_eye_sees_grass_in_front_of_the_horizon(world, parts_seen):
    """Blades (drawn magenta here) hide most of the horizon from a camera 3 cm up and
    fill much of the view down to 10 degrees below it."""
    horizon, below = [], []
    for seed in range(3):
        for blade in parts_seen(world(seed), ("grass",), [10 * seed, 10 * seed + 1],
                                camera_height=0.03):
            rows = len(blade) // 2         # the horizon between rows rows - 1 and rows
            horizon.append(blade[rows - 1:rows + 1].mean())
            below.append(blade[rows:rows + 8].mean())                   # 0-10 degrees down
    assert np.mean(horizon) > 0.8 and np.mean(below) > 0.4


def test_robot_drives_through_grass_and_bumps_into_shrubs_and_rocks(
        world, part, drive, clear_start_facing):
    scene = world(1)
    feet = part(scene, "grass").triangles[:, 0, :2]
    rng = np.random.default_rng(0)
    (xmin, ymin), (xmax, ymax) = scene.bounds
    for _ in range(500):            # a clear 1 m line through many blades
        start, a = rng.uniform((xmin, ymin), (xmax, ymax)), rng.uniform(-math.pi, math.pi)
        line = start + np.linspace(0, 1.2, 25)[:, None] * (math.cos(a), math.sin(a))
        near = np.min(np.linalg.norm(feet[:, None] - line[None], axis=2), axis=1) < 0.16
        if clearances(scene, line).min() > 0.3 and near.sum() > 40:
            break
    else:
        raise AssertionError("no clear line through the grass")
    collided, pose = drive(scene, (*start, a), 35)
    assert not collided and math.dist(pose[:2], start) > 0.7
    solids = part(scene, "shrubs_and_rocks")
    lump = solids.vertices[solids.faces[solids.solids[0]]].reshape(-1, 3)
    centre = lump[:, :2].mean(axis=0)
    reach = np.linalg.norm(lump[:, :2] - centre, axis=1).max()
    start = clear_start_facing(scene, centre, reach + 0.4,
                               np.linspace(0, 2 * math.pi, 12, endpoint=False), "the lump")
    collided, pose = drive(scene, start, 40)
    assert collided and math.dist(pose[:2], centre) > 0.15
