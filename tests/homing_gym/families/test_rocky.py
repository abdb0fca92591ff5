"""The rocky family: boulders of many sizes and outcrops on grey-brown gravel with the
floor between them reachable, a jagged skyline all round, rocks the robot bumps into and
tufts it drives through."""

import math

import numpy as np

from homing_gym.paths import regions

FAMILY = "rocky"
PASSABLE = {"ground", "ridge", "mountains", "far_rocks", "rock_patches", "tufts"}


def _rocks(part):
    """Floor centre (x, y), width across and height (metres) of each solid of ``part``."""
    rocks = []
    for faces in part.solids:
        corners = part.vertices[np.unique(part.faces[faces])]
        centre = (corners[:, :2].min(axis=0) + corners[:, :2].max(axis=0)) / 2
        rocks.append((*centre, np.ptp(corners[:, :2], axis=0).max(), corners[:, 2].max()))
    return np.array(rocks)


def test_worlds_are_fenced_squares_where_only_rocks_collide_within_30_m(world):
    for w in map(world, range(6)):
        assert w.name == "rocky" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 12.0
        assert [p.name for p in w.meshes if p.collision] == ["rocks"]
        assert {p.name for p in w.meshes if not p.collision} == PASSABLE
        assert np.hypot(*np.concatenate([p.vertices[:, :2] for p in w.meshes]).T).max() < 30.0


def test_the_generator_declares_the_solids_trimesh_would_find(world,
                                                              assert_solids_as_trimesh_finds):
    assert_solids_as_trimesh_finds(world(2).meshes)


def test_boulders_of_many_sizes_on_grey_brown_gravel_and_a_reachable_floor(world, part,
                                                                           blocked_share):
    for seed in range(6):
        scene = world(seed)
        rocks = _rocks(part(scene, "rocks"))
        half = scene.bounds[1][0]
        assert np.all(np.abs(rocks[:, :2]).max(axis=1) < half)        # all on the square
        assert len(rocks) >= 10
        assert rocks[:, 2].min() < 0.3 and rocks[:, 2].max() > 1.0      # pebbles to boulders
        assert rocks[:, 3].max() > 0.5                                 # outcrops stand tall
        ground = part(scene, "ground").face_colors
        saturation = np.ptp(ground, axis=1) / ground.max(axis=1)
        assert np.median(saturation) < 0.4                             # greys and browns,
        assert np.all(ground[:, 0] >= ground[:, 1]) and np.all(ground[:, 1] >= ground[:, 2])
        points = np.random.default_rng(0).uniform(-half, half, (2000, 2))
        assert 0.03 < blocked_share(scene, points) < 0.4               # rocky, not walled
        assert regions(scene, 0.165, 0.04).max() == 1                 # one floor, no pockets


def test_a_jagged_skyline_rings_the_world(world, sky_seen):
    """Seen from the floor with a magenta sky, the skyline (the lowest sky pixel of each
    column) is more than 5 degrees up all round, rises and falls by 4 degrees or more
    (peaks and notches) and leaves the sky above 25 degrees in most directions."""
    for seed in range(3):
        sky = sky_seen(world(seed), seed)
        lowest = np.array([np.flatnonzero(column).max() if column.any() else -1
                           for column in sky.T])
        skyline = 30.0 - 1.25 * (lowest + 1)               # degrees: 1.25 a row from 30 up
        assert skyline.min() > 5.0
        assert np.percentile(skyline, 90) - np.percentile(skyline, 10) >= 4.0
        assert np.median(skyline) < 25.0


def test_robot_bumps_into_a_boulder_and_drives_through_a_tuft(world, part, drive,
                                                              clear_start_facing, line_through):
    scene = world(0)
    rocks = _rocks(part(scene, "rocks"))
    x, y, across, _ = rocks[(rocks[:, 2] > 0.3) & (rocks[:, 2] < 0.8)][0]   # a middling one
    start = clear_start_facing(scene, np.array([x, y]), across / 2 + 0.45,
                               np.linspace(0, 2 * math.pi, 24, endpoint=False), "the boulder")
    collided, pose = drive(scene, start, 40)
    assert collided and math.dist(pose[:2], (x, y)) > 0.16
    blades = part(scene, "tufts").triangles     # a tuft with a clear 1.2 m line through it
    start = line_through(scene, blades[:, 0, :2], what="a tuft")
    collided, pose = drive(scene, start, 35)
    assert not collided and math.dist(pose[:2], start[:2]) > 0.9
