"""The labs family: worlds reproducible from the seed and distinct across seeds, one hall
far more cluttered than an office (benches along the walls, islands, boxes of many sizes
and colours on the floor) yet reached everywhere through aisles, clutter the robot bumps
into and things on benches and shelves that block nothing, LocalHoming episodes in every
world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.labs import labs_scene
from homing_gym.scenes.families.offices import offices_scene
from homing_gym.scenes.mesh_part import MeshPart

FORWARD = np.array([1.0, 0.0], np.float32)


def _world(seed):
    return labs_scene(np.random.default_rng(seed))


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
    assert _signature(_world(5)) == _signature(_world(5))
    worlds = [_world(seed) for seed in range(6)]
    assert len({_signature(w) for w in worlds}) == 6
    for w in worlds:
        assert w.name == "labs" and w.ground_plane and not w.fence
        assert 6.0 <= w.size[0] <= 12.0 and 5.0 <= w.size[1] <= 9.0
        assert all(2.0 <= wall.height <= 3.0 for wall in w.walls)
        assert {p.name for p in w.meshes if not p.collision} <= {"on_top"}


def test_the_generator_declares_the_solids_trimesh_would_find():
    for part in _world(3).meshes:
        found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
        assert sorted(map(tuple, part.solids)) == sorted(map(tuple, found)), part.name


def test_a_hall_far_more_cluttered_than_an_office_with_boxes_of_many_sizes_and_colours():
    blocked = {"labs": [], "offices": []}
    for seed in range(5):
        for name, build in (("labs", labs_scene), ("offices", offices_scene)):
            scene = build(np.random.default_rng(seed))
            blocked[name].append(np.mean(clearances(scene, _grid(scene)) <= 0.0))
        scene = _world(seed)
        names = [lm.name for lm in scene.landmarks]
        assert names.count("bench") + len(scene.metadata["islands"]) >= 2
        boxes = np.array(scene.metadata["floor_boxes"]).reshape(-1, 4)
        middles = (boxes[:, :2] + boxes[:, 2:]) / 2
        assert len(boxes) >= 3 and np.all(clearances(scene, middles) == 0.0)
        part = _part(scene, "boxes")
        assert len(part.solids) >= 5
        assert len(np.unique(part.face_colors.round(2), axis=0)) >= 5
        assert np.ptp((boxes[:, 2:] - boxes[:, :2]).max(axis=1)) > 0.2     # many sizes
    assert np.mean(blocked["labs"]) > 1.6 * np.mean(blocked["offices"])


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
    env = make_env(scene=SceneFactory(build=labs_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "labs"


def test_clutter_blocks_and_what_stands_on_benches_and_shelves_does_not():
    scene = _world(2)
    grid = _grid(scene)
    free = clearances(scene, grid)
    without = lambda name: replace(scene, meshes=tuple(  # noqa: E731
        p for p in scene.meshes if p.name != name))
    assert np.array_equal(free, clearances(without("on_top"), grid))
    for name in ("boxes", "furniture"):
        opened = clearances(without(name), grid)
        assert np.all(opened >= free) and np.any(opened > free + 0.1), name


def test_robot_bumps_into_a_floor_box(make_env):
    scene = _world(0)
    env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
    for x0, y0, x1, y1 in scene.metadata["floor_boxes"]:
        for edge, yaw in ((((x0 + x1) / 2, y0), math.pi / 2), (((x0 + x1) / 2, y1), -math.pi / 2),
                          ((x0, (y0 + y1) / 2), 0.0), ((x1, (y0 + y1) / 2), math.pi)):
            ahead = np.array([math.cos(yaw), math.sin(yaw)])
            line = np.array(edge) - np.linspace(0.2, 0.6, 9)[:, None] * ahead
            if clearances(scene, line).min() > 0.16:        # a clear run up to the box
                break
        else:
            continue
        break
    else:
        raise AssertionError("no box with a clear side")
    env.reset(seed=0, options={"start": (*line[-1], yaw)})
    collided = False
    for _ in range(40):
        _, _, _, _, info = env.step(FORWARD)
        collided |= info["collision"]
    assert collided
    gap = max(x0 - info["pose"][0], info["pose"][0] - x1, y0 - info["pose"][1],
              info["pose"][1] - y1)
    assert 0.12 < gap < 0.22                        # stopped at the box
