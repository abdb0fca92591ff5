"""The forest family: worlds reproducible from the seed and distinct across seeds, a dense
stand of trunks on a reachable floor, a far view that is a wall of trunks, trunks and
logs the robot bumps into and ferns it drives through, LocalHoming episodes in every
world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.forest import forest_scene
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import random_nature_scene

FORWARD = np.array([1.0, 0.0], np.float32)
BLOCKING = {"trunks", "undergrowth", "logs"}
PASSABLE = {"ground", "far_forest", "far_trunks", "crowns", "ferns"}


def _world(seed):
    return forest_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes())
                   for p in scene.meshes)
    return scene.bounds, scene.sky_color, scene.appearance, meshes


def _part(scene, name):
    return next(p for p in scene.meshes if p.name == name)


def _feet(part):
    """Floor centre (x, y) and radius (metres) of each solid of ``part`` at the ground."""
    feet = []
    for faces in part.solids:
        corners = part.vertices[np.unique(part.faces[faces])]
        low = corners[corners[:, 2] < 0.05, :2]
        centre = low.mean(axis=0)
        feet.append((*centre, np.linalg.norm(low - centre, axis=1).max()))
    return np.array(feet)


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(7)) == _signature(_world(7))
    worlds = [_world(seed) for seed in range(6)]
    assert len({_signature(w) for w in worlds}) == 6
    for w in worlds:
        assert w.name == "forest" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 12.0
        assert {p.name for p in w.meshes if p.collision} <= BLOCKING
        assert {p.name for p in w.meshes if not p.collision} == PASSABLE
        assert np.hypot(*np.concatenate([p.vertices[:, :2] for p in w.meshes]).T).max() < 30.0


def test_the_generator_declares_the_solids_trimesh_would_find():
    for part in _world(2).meshes:
        found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
        assert sorted(map(tuple, part.solids)) == sorted(map(tuple, found)), part.name


def test_a_dense_stand_of_trunks_of_many_sizes_on_a_reachable_floor():
    densities, nature, radii = [], [], []
    for seed in range(6):
        scene = _world(seed)
        trunks = _feet(_part(scene, "trunks"))
        (xmin, ymin), (xmax, ymax) = scene.bounds
        assert np.all((np.abs(trunks[:, :2]) < xmax))             # all on the square
        assert len(trunks) >= 10 and np.sum(np.hypot(trunks[:, 0], trunks[:, 1]) < 3.0) >= 3
        densities.append(len(trunks) / (scene.size[0] * scene.size[1]))
        radii.extend(trunks[:, 2])
        other = random_nature_scene(np.random.default_rng(seed))
        half = other.bounds[1][0]
        inside = np.abs(_feet(_part(other, "trunks"))[:, :2]).max(axis=1) < half
        nature.append(inside.sum() / (other.size[0] * other.size[1]))
        far = _part(scene, "far_trunks")                          # 12 faces a trunk
        assert len(far.faces) // 12 >= 120
        assert np.abs(far.vertices[:, :2]).max(axis=1).min() > xmax  # all beyond the fence
        assert regions(scene, 0.165, 0.04).max() == 1                 # one floor, no pockets
    assert np.mean(densities) > 3 * np.mean(nature)
    assert min(radii) < 0.1 and max(radii) > 0.25 and max(radii) <= 0.41


def test_only_trunks_bushes_and_logs_block_the_robot():
    scene = _world(3)
    (xmin, ymin), (xmax, ymax) = scene.bounds
    gx, gy = np.meshgrid(np.linspace(xmin, xmax, 60), np.linspace(ymin, ymax, 60))
    grid = np.stack([gx.ravel(), gy.ravel()], 1)

    def without(*names):
        return replace(scene, meshes=tuple(p for p in scene.meshes if p.name not in names))

    free = clearances(scene, grid)
    assert np.array_equal(free, clearances(without(*PASSABLE), grid))
    for blocking in BLOCKING & {p.name for p in scene.meshes}:
        opened = clearances(without(blocking), grid)
        assert np.all(opened >= free) and np.any(opened > free + 0.1), blocking


def test_the_far_view_is_a_wall_of_trunks(make_env):
    """Seen from the floor with a magenta sky, little sky shows between 10 and 25 degrees
    above the horizon (tall trunks all round), where random_nature shows mostly sky."""
    def sky_share(scene, seed):
        plain = replace(scene, appearance=replace(scene.appearance, sky_zenith=None))
        env = make_env(scene=plain, start_distance=(0.3, 2.0), camera_height=0.2,
                       sky_color=(1.0, 0.0, 1.0), panorama_shape=(48, 256))
        pano = env.reset(seed=seed)[0]["panorama"].astype(int)
        sky = (pano[..., 0] > 200) & (pano[..., 1] < 40) & (pano[..., 2] > 200)
        return sky[4:16].mean()                # 1.25 degrees a row: 25 to 10 degrees up
    for seed in range(3):
        assert sky_share(_world(seed), seed) < 0.25
    assert sky_share(random_nature_scene(np.random.default_rng(0)), 0) > 0.5


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=forest_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "forest"


def _drive(env, start, steps):
    env.reset(seed=0, options={"start": start})
    collided = False
    for _ in range(steps):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    return collided, info["pose"]


def _clear_start_facing(scene, centre, gap, directions):
    """A start pose ``gap`` metres from ``centre`` facing it, from one of ``directions``
    (radians), 0.25 m clear."""
    for a in directions:
        start = centre - gap * np.array([math.cos(a), math.sin(a)])
        if clearances(scene, [start])[0] > 0.25:
            return (*start, a)
    raise AssertionError("no clear start facing it")


def test_robot_bumps_into_trunks_and_logs_and_drives_through_ferns(make_env):
    scene = _world(0)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    x, y, radius = _feet(_part(scene, "trunks"))[0]
    start = _clear_start_facing(scene, np.array([x, y]), radius + 0.45,
                                np.linspace(0, 2 * math.pi, 24, endpoint=False))
    collided, pose = _drive(env, start, 40)
    assert collided and math.dist(pose[:2], (x, y)) > radius + 0.15
    log = _part(scene, "logs")
    low = log.vertices[np.unique(log.faces[log.solids[0]])]
    low = low[low[:, 2] < 0.05, :2]
    middle = low.mean(axis=0)
    axis = np.linalg.svd(low - middle)[2][0]                  # along the log
    across = math.atan2(axis[0], -axis[1])
    start = _clear_start_facing(scene, middle, 0.7, (across, across + math.pi))
    collided, pose = _drive(env, start, 40)
    assert collided and math.dist(pose[:2], middle) > 0.2
    fronds = _part(scene, "ferns").triangles
    for centre in fronds[::7, 0, :2]:         # a clump with a clear 1.2 m line through it
        a = math.atan2(-centre[1], -centre[0])               # towards the middle
        start = centre - 0.6 * np.array([math.cos(a), math.sin(a)])
        line = start + np.linspace(0, 1.2, 25)[:, None] * (math.cos(a), math.sin(a))
        if clearances(scene, line).min() > 0.3:
            break
    else:
        raise AssertionError("no clear line through a fern")
    collided, pose = _drive(env, (*start, a), 35)
    assert not collided and math.dist(pose[:2], start) > 0.9
