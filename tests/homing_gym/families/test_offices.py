"""The offices family: worlds reproducible from the seed and distinct across seeds, an
open-plan floor of desks in rows with chairs, windows high on the walls and furniture
along them, every part of it reached through aisles, desks and chairs the robot bumps
into and monitors that block nothing, LocalHoming episodes in every world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.offices import offices_scene
from homing_gym.scenes.mesh_part import MeshPart

FORWARD = np.array([1.0, 0.0], np.float32)


def _world(seed):
    return offices_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes())
                   for p in scene.meshes)
    return (scene.bounds, scene.walls, scene.landmarks, scene.floor_color, scene.floor_texture,
            scene.sky_color, scene.appearance, meshes)


def _part(scene, name):
    return next(p for p in scene.meshes if p.name == name)


def _grid(scene, step=0.1) -> np.ndarray:
    (xmin, ymin), (xmax, ymax) = scene.bounds
    gx, gy = np.meshgrid(np.arange(xmin + step / 2, xmax, step),
                         np.arange(ymin + step / 2, ymax, step))
    return np.stack([gx.ravel(), gy.ravel()], 1)


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(4)) == _signature(_world(4))
    worlds = [_world(seed) for seed in range(6)]
    assert len({_signature(w) for w in worlds}) == 6
    for w in worlds:
        assert w.name == "offices" and w.ground_plane and not w.fence
        assert 8.0 <= w.size[0] <= 16.0 and 6.0 <= w.size[1] <= 12.0
        assert all(2.0 <= wall.height <= 3.0 for wall in w.walls)
        assert {p.name for p in w.meshes if not p.collision} <= {"on_top"}
    assert len({w.floor_texture for w in worlds} | {w.walls[0].texture for w in worlds}) >= 4


def test_the_generator_declares_the_solids_trimesh_would_find():
    for part in _world(2).meshes:
        found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
        assert sorted(map(tuple, part.solids)) == sorted(map(tuple, found)), part.name


def test_desks_stand_in_rows_with_chairs_windows_above_and_furniture_along_the_walls():
    desks = chairs = 0
    for seed in range(6):
        scene = _world(seed)
        tops = np.array(scene.metadata["desks"]).reshape(-1, 4)
        assert len(tops) >= 4
        sizes = np.sort(tops[:, 2:] - tops[:, :2], axis=1)
        assert np.all((sizes[:, 0] > 0.68) & (sizes[:, 0] < 0.8))
        assert np.all((sizes[:, 1] > 1.18) & (sizes[:, 1] < 1.6))
        # in rows: the desks' edges line up, a few lines for many desks
        lines = min(len(np.unique(tops[:, k].round(2))) for k in (1, 0))
        assert lines <= len(tops) / 2
        # the floor under a desk and between its legs is blocked, as is a chair's foot
        middles = (tops[:, :2] + tops[:, 2:]) / 2
        assert np.all(clearances(scene, middles) == 0.0)
        assert np.all(clearances(scene, scene.metadata["chairs"]) == 0.0)
        desks, chairs = desks + len(tops), chairs + len(scene.metadata["chairs"])
        names = [lm.name for lm in scene.landmarks]
        windows = [lm for lm in scene.landmarks if lm.name == "window"]
        assert windows and all(lm.base >= 0.8 and lm.base + lm.height <= scene.walls[0].height
                               for lm in windows)
        assert sum(n in ("cabinet", "locker", "bookcase", "printer") for n in names) >= 2
        screens = _part(scene, "on_top").vertices
        assert screens[:, 2].min() >= 0.72 and len(screens) >= 16 * len(tops)
    assert desks >= 40 and chairs >= 0.7 * desks


def test_every_part_of_the_floor_is_reached_through_aisles():
    for seed in range(4):
        scene = _world(seed)
        labels = regions(scene, 0.22, 0.05)          # the task's clearance: no pocket
        sizes = np.bincount(labels.ravel())[1:]
        main = int(np.argmax(sizes)) + 1
        for label in set(range(1, len(sizes) + 1)) - {main}:
            extent = np.ptp(np.argwhere(labels == label), axis=0).max() * 0.05
            assert extent < 0.3, (seed, extent)
        wide = np.bincount(regions(scene, 0.3, 0.05).ravel())[1:]    # 0.6 m aisles
        assert wide.max() >= 0.97 * wide.sum()


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=offices_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "offices"


def test_only_furniture_blocks_and_monitors_do_not():
    scene = _world(1)
    grid = _grid(scene)
    free = clearances(scene, grid)
    without = lambda name: replace(scene, meshes=tuple(  # noqa: E731
        p for p in scene.meshes if p.name != name))
    assert np.array_equal(free, clearances(without("on_top"), grid))
    opened = clearances(without("furniture"), grid)
    assert np.all(opened >= free) and np.mean(opened > free + 0.1) > 0.05


def test_robot_bumps_into_a_desk(make_env):
    scene = _world(0)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    for x0, y0, x1, y1 in scene.metadata["desks"]:
        for edge, yaw in ((((x0 + x1) / 2, y0), math.pi / 2), (((x0 + x1) / 2, y1), -math.pi / 2),
                          ((x0, (y0 + y1) / 2), 0.0), ((x1, (y0 + y1) / 2), math.pi)):
            ahead = np.array([math.cos(yaw), math.sin(yaw)])
            line = np.array(edge) - np.linspace(0.2, 0.7, 11)[:, None] * ahead
            if clearances(scene, line).min() > 0.16:        # a clear run up to the desk
                break
        else:
            continue
        break
    else:
        raise AssertionError("no desk with a clear side")
    env.reset(seed=0, options={"start": (*line[-1], yaw)})
    collided = False
    for _ in range(40):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    assert collided
    gap = max(x0 - info["pose"][0], info["pose"][0] - x1, y0 - info["pose"][1],
              info["pose"][1] - y1)
    assert 0.12 < gap < 0.25                       # stopped at the desk's edge
