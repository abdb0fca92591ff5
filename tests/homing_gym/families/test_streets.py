"""The streets family: worlds reproducible from the seed and distinct across seeds, a
street or a plaza lined by building blocks with windowed facades and a skyline beyond,
little sky between 10 and 25 degrees up, furniture the robot bumps into and flat marks it
drives over, LocalHoming episodes in every world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.streets import REACH, streets_scene
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import random_nature_scene

FORWARD = np.array([1.0, 0.0], np.float32)
PASSABLE = {"ground", "road", "marks", "crowns", "water"}


def _world(seed):
    return streets_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes(),
                    None if p.texture is None else p.texture.tobytes()) for p in scene.meshes)
    return scene.bounds, scene.sky_color, scene.appearance, meshes


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


def _part(scene, name):
    return next(p for p in scene.meshes if p.name == name)


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(7)) == _signature(_world(7))
    worlds = [_world(seed) for seed in range(8)]
    assert len({_signature(w) for w in worlds}) == 8
    assert len({w.bounds for w in worlds}) == 8
    assert {w.metadata["layout"] for w in worlds} == {"street", "plaza"}
    for w in worlds:
        assert w.name == "streets" and w.fence and not w.ground_plane and not w.walls
        width, depth = w.size
        assert 6.0 <= width <= 12.0 and 8.0 <= depth <= 20.0
        assert {p.name for p in w.meshes if not p.collision} <= PASSABLE
        assert sum(len(p.faces) for p in w.meshes) < 4000          # cheap to cast


def test_the_generator_declares_the_solids_trimesh_would_find():
    for part in _world(2).meshes:
        if part.solid_faces:
            found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
            assert sorted(map(tuple, part.solids)) == sorted(map(tuple, found)), part.name


def test_blocks_line_the_floor_with_windowed_facades_and_a_skyline_beyond():
    for seed in range(10):
        scene = _world(seed)
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


def test_little_sky_shows_between_the_blocks(make_env):
    """With a magenta sky, little of it shows 10-25 degrees above the horizon, where
    random_nature shows mostly sky."""
    def sky_share(scene, seed):
        plain = replace(scene, appearance=replace(scene.appearance, sky_zenith=None))
        env = make_env(scene=plain, start_distance=(0.3, 2.0), camera_height=0.2,
                       sky_color=(1.0, 0.0, 1.0), panorama_shape=(48, 256))
        pano = env.reset(seed=seed)[0]["panorama"].astype(int)
        sky = (pano[..., 0] > 200) & (pano[..., 1] < 40) & (pano[..., 2] > 200)
        return sky[4:16].mean()                # 1.25 degrees a row: 25 to 10 degrees up
    assert max(sky_share(_world(seed), seed) for seed in range(3)) < 0.3
    assert sky_share(random_nature_scene(np.random.default_rng(0)), 0) > 0.5


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=streets_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "streets"


def test_only_furniture_and_buildings_block_the_robot():
    scene = _world(0)
    (xmin, ymin), (xmax, ymax) = scene.bounds
    gx, gy = np.meshgrid(np.linspace(xmin, xmax, 50), np.linspace(ymin, ymax, 80))
    grid = np.stack([gx.ravel(), gy.ravel()], 1)
    free = clearances(scene, grid)
    passable = replace(scene, meshes=tuple(p for p in scene.meshes if p.name not in PASSABLE))
    assert np.array_equal(free, clearances(passable, grid))
    bare = replace(scene, meshes=tuple(p for p in scene.meshes if p.name != "furniture"))
    opened = clearances(bare, grid)
    assert np.all(opened >= free) and np.any(opened > free + 0.3)


def _drive(env, start, steps):
    env.reset(seed=0, options={"start": start})
    collided = False
    for _ in range(steps):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    return collided, info["pose"]


def test_robot_bumps_into_furniture_and_drives_over_road_marks(make_env):
    scene = _world(0)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    furniture = _part(scene, "furniture")
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
                collided, pose = _drive(env, (*start, a), 40)
                assert collided and np.abs(pose[:2] - centre).max() > 0.1
                bumped += 1
                break
        if bumped == 2:
            break
    assert bumped == 2
    marks = _part(scene, "marks").triangles
    for corner in marks[::5, 0, :2]:              # a clear 1.2 m line across a mark
        a = math.atan2(-corner[1], -corner[0]) + 0.3
        heading = np.array([math.cos(a), math.sin(a)])
        start = corner - 0.6 * heading
        line = start + np.linspace(0, 1.4, 29)[:, None] * heading
        if clearances(scene, line).min() > 0.3:
            break
    else:
        raise AssertionError("no clear line across a mark")
    collided, pose = _drive(env, (*start, a), 35)
    assert not collided and math.dist(pose[:2], start) > 0.9
