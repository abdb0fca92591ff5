"""The forest family: a dense stand of trunks on a reachable floor, a far view that is a
wall of trunks, trunks and logs the robot bumps into and ferns it drives through."""

import math

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes.base import clearances

FAMILY = "forest"
BLOCKING = {"trunks", "undergrowth", "logs"}
PASSABLE = {"ground", "far_forest", "far_trunks", "crowns", "ferns"}


def _feet(part):
    """Floor centre (x, y) and radius (metres) of each solid of ``part`` at the ground."""
    feet = []
    for faces in part.solids:
        corners = part.vertices[np.unique(part.faces[faces])]
        low = corners[corners[:, 2] < 0.05, :2]
        centre = low.mean(axis=0)
        feet.append((*centre, np.linalg.norm(low - centre, axis=1).max()))
    return np.array(feet)


def test_worlds_are_fenced_squares_of_blocking_and_passable_parts_within_30_m(world):
    for w in map(world, range(6)):
        assert w.name == "forest" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 12.0
        assert {p.name for p in w.meshes if p.collision} <= BLOCKING
        assert {p.name for p in w.meshes if not p.collision} == PASSABLE
        assert np.hypot(*np.concatenate([p.vertices[:, :2] for p in w.meshes]).T).max() < 30.0


def test_the_generator_declares_the_solids_trimesh_would_find(world,
                                                              assert_solids_as_trimesh_finds):
    assert_solids_as_trimesh_finds(world(2).meshes)


def test_a_dense_stand_of_trunks_of_many_sizes_on_a_reachable_floor(world, part):
    densities, nature, radii = [], [], []
    for seed in range(6):
        scene = world(seed)
        trunks = _feet(part(scene, "trunks"))
        (xmin, ymin), (xmax, ymax) = scene.bounds
        assert np.all((np.abs(trunks[:, :2]) < xmax))             # all on the square
        assert len(trunks) >= 10 and np.sum(np.hypot(trunks[:, 0], trunks[:, 1]) < 3.0) >= 3
        densities.append(len(trunks) / (scene.size[0] * scene.size[1]))
        radii.extend(trunks[:, 2])
        other = world(seed, "random_nature")
        half = other.bounds[1][0]
        inside = np.abs(_feet(part(other, "trunks"))[:, :2]).max(axis=1) < half
        nature.append(inside.sum() / (other.size[0] * other.size[1]))
        far = part(scene, "far_trunks")                           # 12 faces a trunk
        assert len(far.faces) // 12 >= 120
        assert np.abs(far.vertices[:, :2]).max(axis=1).min() > xmax  # all beyond the fence
        assert regions(scene, 0.165, 0.04).max() == 1                 # one floor, no pockets
    assert np.mean(densities) > 3 * np.mean(nature)
    assert min(radii) < 0.1 and max(radii) > 0.25 and max(radii) <= 0.41


def test_only_trunks_bushes_and_logs_block_the_robot(world, floor_grid, without):
    scene = world(3)
    grid = floor_grid(scene, shape=(60, 60))
    free = clearances(scene, grid)
    assert np.array_equal(free, clearances(without(scene, *PASSABLE), grid))
    for blocking in BLOCKING & {p.name for p in scene.meshes}:
        opened = clearances(without(scene, blocking), grid)
        assert np.all(opened >= free) and np.any(opened > free + 0.1), blocking


def test_the_far_view_is_a_wall_of_trunks(world, sky_seen):
    """Seen from the floor with a magenta sky, little sky shows between 10 and 25 degrees
    above the horizon (tall trunks all round), where random_nature shows mostly sky."""
    for seed in range(3):
        assert sky_seen(world(seed), seed)[4:16].mean() < 0.25      # 25 to 10 degrees up
    assert sky_seen(world(0, "random_nature"), 0)[4:16].mean() > 0.5


def test_robot_bumps_into_trunks_and_logs_and_drives_through_ferns(
        world, part, drive, clear_start_facing, line_through):
    scene = world(0)
    x, y, radius = _feet(part(scene, "trunks"))[0]
    start = clear_start_facing(scene, np.array([x, y]), radius + 0.45,
                               np.linspace(0, 2 * math.pi, 24, endpoint=False), "a trunk")
    collided, pose = drive(scene, start, 40)
    assert collided and math.dist(pose[:2], (x, y)) > radius + 0.15
    log = part(scene, "logs")
    low = log.vertices[np.unique(log.faces[log.solids[0]])]
    low = low[low[:, 2] < 0.05, :2]
    middle = low.mean(axis=0)
    axis = np.linalg.svd(low - middle)[2][0]                  # along the log
    across = math.atan2(axis[0], -axis[1])
    start = clear_start_facing(scene, middle, 0.7, (across, across + math.pi), "a log")
    collided, pose = drive(scene, start, 40)
    assert collided and math.dist(pose[:2], middle) > 0.2
    fronds = part(scene, "ferns").triangles        # a clump with a clear 1.2 m line through it
    start = line_through(scene, fronds[::7, 0, :2], what="a fern")
    collided, pose = drive(scene, start, 35)
    assert not collided and math.dist(pose[:2], start[:2]) > 0.9
