"""The rocky family: worlds reproducible from the seed and distinct across seeds, boulders
of many sizes and outcrops on grey-brown gravel with the floor between them reachable, a
jagged skyline all round, rocks the robot bumps into and tufts it drives through,
LocalHoming episodes in every world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.rocky import rocky_scene
from homing_gym.scenes.mesh_part import MeshPart

FORWARD = np.array([1.0, 0.0], np.float32)
PASSABLE = {"ground", "ridge", "mountains", "far_rocks", "rock_patches", "tufts"}


def _world(seed):
    return rocky_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes())
                   for p in scene.meshes)
    return scene.bounds, scene.sky_color, scene.appearance, meshes


def _part(scene, name):
    return next(p for p in scene.meshes if p.name == name)


def _rocks(scene):
    """Floor centre (x, y), width across and height (metres) of each colliding rock."""
    part = _part(scene, "rocks")
    rocks = []
    for faces in part.solids:
        corners = part.vertices[np.unique(part.faces[faces])]
        centre = (corners[:, :2].min(axis=0) + corners[:, :2].max(axis=0)) / 2
        rocks.append((*centre, np.ptp(corners[:, :2], axis=0).max(), corners[:, 2].max()))
    return np.array(rocks)


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(7)) == _signature(_world(7))
    worlds = [_world(seed) for seed in range(6)]
    assert len({_signature(w) for w in worlds}) == 6
    for w in worlds:
        assert w.name == "rocky" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 12.0
        assert [p.name for p in w.meshes if p.collision] == ["rocks"]
        assert {p.name for p in w.meshes if not p.collision} == PASSABLE
        assert np.hypot(*np.concatenate([p.vertices[:, :2] for p in w.meshes]).T).max() < 30.0


def test_the_generator_declares_the_solids_trimesh_would_find():
    for part in _world(2).meshes:
        found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
        assert sorted(map(tuple, part.solids)) == sorted(map(tuple, found)), part.name


def test_boulders_of_many_sizes_on_grey_brown_gravel_and_a_reachable_floor():
    for seed in range(6):
        scene = _world(seed)
        rocks = _rocks(scene)
        half = scene.bounds[1][0]
        assert np.all(np.abs(rocks[:, :2]).max(axis=1) < half)        # all on the square
        assert len(rocks) >= 10
        assert rocks[:, 2].min() < 0.3 and rocks[:, 2].max() > 1.0      # pebbles to boulders
        assert rocks[:, 3].max() > 0.5                                 # outcrops stand tall
        ground = _part(scene, "ground").face_colors
        saturation = np.ptp(ground, axis=1) / ground.max(axis=1)
        assert np.median(saturation) < 0.4                             # greys and browns,
        assert np.all(ground[:, 0] >= ground[:, 1]) and np.all(ground[:, 1] >= ground[:, 2])
        blocked = clearances(scene, np.random.default_rng(0).uniform(-half, half, (2000, 2)))
        assert 0.03 < np.mean(blocked <= 0) < 0.4                      # rocky, not walled
        assert regions(scene, 0.165, 0.04).max() == 1                 # one floor, no pockets


def test_a_jagged_skyline_rings_the_world(make_env):
    """Seen from the floor with a magenta sky, the skyline (the lowest sky pixel of each
    column) is more than 5 degrees up all round, rises and falls by 4 degrees or more
    (peaks and notches) and leaves the sky above 25 degrees in most directions."""
    for seed in range(3):
        scene = _world(seed)
        plain = replace(scene, appearance=replace(scene.appearance, sky_zenith=None))
        env = make_env(scene=plain, start_distance=(0.3, 2.0), camera_height=0.2,
                       sky_color=(1.0, 0.0, 1.0), panorama_shape=(48, 256))
        pano = env.reset(seed=seed)[0]["panorama"].astype(int)
        sky = (pano[..., 0] > 200) & (pano[..., 1] < 40) & (pano[..., 2] > 200)
        lowest = np.array([np.flatnonzero(column).max() if column.any() else -1
                           for column in sky.T])
        skyline = 30.0 - 1.25 * (lowest + 1)               # degrees: 1.25 a row from 30 up
        assert skyline.min() > 5.0
        assert np.percentile(skyline, 90) - np.percentile(skyline, 10) >= 4.0
        assert np.median(skyline) < 25.0


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=rocky_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "rocky"


def _drive(env, start, steps):
    env.reset(seed=0, options={"start": start})
    collided = False
    for _ in range(steps):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    return collided, info["pose"]


def test_robot_bumps_into_a_boulder_and_drives_through_a_tuft(make_env):
    scene = _world(0)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    rocks = _rocks(scene)
    x, y, across, _ = rocks[(rocks[:, 2] > 0.3) & (rocks[:, 2] < 0.8)][0]   # a middling one
    for a in np.linspace(0, 2 * math.pi, 24, endpoint=False):
        start = np.array([x, y]) - (across / 2 + 0.45) * np.array([math.cos(a), math.sin(a)])
        if clearances(scene, [start])[0] > 0.25:
            break
    else:
        raise AssertionError("no clear start facing the boulder")
    collided, pose = _drive(env, (*start, a), 40)
    assert collided and math.dist(pose[:2], (x, y)) > 0.16
    blades = _part(scene, "tufts").triangles
    for foot in blades[:, 0, :2]:              # a tuft with a clear 1.2 m line through it
        a = math.atan2(-foot[1], -foot[0])                   # towards the middle
        start = foot - 0.6 * np.array([math.cos(a), math.sin(a)])
        line = start + np.linspace(0, 1.2, 25)[:, None] * (math.cos(a), math.sin(a))
        if clearances(scene, line).min() > 0.3:
            break
    else:
        raise AssertionError("no clear line through a tuft")
    collided, pose = _drive(env, (*start, a), 35)
    assert not collided and math.dist(pose[:2], start) > 0.9
