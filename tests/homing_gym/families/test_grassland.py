"""The grassland family: worlds reproducible from the seed and distinct across seeds, dense
thin grass that fills an ant's-eye view and that the robot drives through, shrubs and
rocks it bumps into, and LocalHoming episodes in every world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.grassland import BLADES, grassland_scene
from homing_gym.scenes.mesh_part import MeshPart

FORWARD = np.array([1.0, 0.0], np.float32)


def _world(seed):
    return grassland_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes())
                   for p in scene.meshes)
    return scene.bounds, scene.sky_color, scene.appearance, meshes


def _grass(scene) -> MeshPart:
    return next(p for p in scene.meshes if p.name == "grass")


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(4)) == _signature(_world(4))
    worlds = [_world(seed) for seed in range(6)]
    assert len({_signature(w) for w in worlds}) == 6
    assert len({w.bounds for w in worlds}) == 6
    assert len({len(_grass(w).faces) for w in worlds}) == 6
    for w in worlds:
        assert w.name == "grassland" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 8.0


def test_grass_is_dense_thin_and_does_not_block():
    for seed in range(3):
        scene = _world(seed)
        grass = _grass(scene)
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
        bare = replace(scene, meshes=tuple(p for p in scene.meshes if p is not grass))
        assert np.array_equal(clearances(scene, feet), clearances(bare, feet))


def test_an_ants_eye_sees_grass_in_front_of_the_horizon(make_env):
    """Blades (drawn magenta here) hide most of the horizon from a camera 3 cm up and
    fill much of the view down to 10 degrees below it."""
    horizon, below = [], []
    for seed in range(3):
        scene = _world(seed)
        grass = _grass(scene)
        magenta = np.tile([1.0, 0.0, 1.0], (len(grass.faces), 1))
        flagged = MeshPart(grass.vertices, grass.faces, magenta, collision=False,
                           name="grass", solid_faces=())
        env = make_env(scene=replace(scene, meshes=tuple(flagged if p is grass else p
                                                         for p in scene.meshes)),
                       start_distance=(0.3, 2.0), camera_height=0.03)
        for k in range(2):
            obs, _ = env.reset(seed=10 * seed + k)
            pano = obs["panorama"].astype(int)
            blade = (pano[..., 1] < 0.3 * pano[..., 0]) & (pano[..., 1] < 0.3 * pano[..., 2])
            rows = len(pano) // 2          # the horizon between rows rows - 1 and rows
            horizon.append(blade[rows - 1:rows + 1].mean())
            below.append(blade[rows:rows + 8].mean())                   # 0-10 degrees down
    assert np.mean(horizon) > 0.8 and np.mean(below) > 0.4


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=grassland_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "grassland"
        assert regions(env.unwrapped.scene, 0.22, 0.05).max() == 1      # one open floor


def _drive(env, start, steps):
    env.reset(seed=0, options={"start": start})
    collided = False
    for _ in range(steps):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    return collided, info["pose"]


def test_robot_drives_through_grass_and_bumps_into_shrubs_and_rocks(make_env):
    scene = _world(1)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    grass = _grass(scene)
    feet = grass.triangles[:, 0, :2]
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
    collided, pose = _drive(env, (*start, a), 35)
    assert not collided and math.dist(pose[:2], start) > 0.7
    solids = next(p for p in scene.meshes if p.name == "shrubs_and_rocks")
    lump = solids.vertices[solids.faces[solids.solids[0]]].reshape(-1, 3)
    centre = lump[:, :2].mean(axis=0)
    reach = np.linalg.norm(lump[:, :2] - centre, axis=1).max()
    for a in np.linspace(0, 2 * math.pi, 12, endpoint=False):   # a clear start facing it
        start = centre - (reach + 0.4) * np.array([math.cos(a), math.sin(a)])
        if clearances(scene, [start])[0] > 0.25:
            break
    else:
        raise AssertionError("no clear start facing the lump")
    collided, pose = _drive(env, (*start, a), 40)
    assert collided and math.dist(pose[:2], centre) > 0.15
