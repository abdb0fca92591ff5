"""Procedural worlds: random_rooms (indoor) and random_nature (outdoor) are reproducible
from the seed, distinct across seeds, connected, and homed in by the oracle."""

import math
from dataclasses import replace

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from homing_gym.paths import shortest_path
from homing_gym.scenes import scene_factory
from homing_gym.scenes.base import clearance, clearances
from homing_train.harness.rollout import rollout

PROCEDURAL = ("random_rooms", "random_nature")


def _scene(name, seed):
    return scene_factory(name).build(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    """What makes two worlds the same: geometry, colours and textures."""
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes())
                   for p in scene.meshes)
    return (scene.bounds, scene.walls, scene.landmarks, scene.floor_color, scene.floor_texture,
            meshes)


@pytest.mark.parametrize("name", PROCEDURAL)
def test_worlds_are_reproducible_and_distinct(name):
    assert _signature(_scene(name, 3)) == _signature(_scene(name, 3))
    signatures = {_signature(_scene(name, seed)) for seed in range(12)}
    assert len(signatures) == 12


def test_rooms_are_all_reachable_through_doors():
    for seed in range(8):
        scene = _scene("random_rooms", seed)
        rooms = scene.metadata["rooms"]
        assert 1 <= len(rooms) <= 6
        centres = []
        for (xmin, ymin), (xmax, ymax) in rooms:
            # a free spot in each room (furniture may stand in its middle)
            gx, gy = np.meshgrid(np.linspace(xmin, xmax, 25), np.linspace(ymin, ymax, 25))
            pts = np.stack([gx.ravel(), gy.ravel()], 1)
            centres.append(tuple(pts[np.argmax(clearances(scene, pts))]))
        for a in centres[1:]:
            path = shortest_path(scene, centres[0], a, radius=0.2)     # raises if cut off
            assert np.allclose(path[0], centres[0]) and np.allclose(path[-1], a)


def test_nature_trunks_and_rocks_block_but_crowns_and_hills_do_not():
    scene = _scene("random_nature", 0)
    parts = {p.name: p for p in scene.meshes}
    assert scene.fence and not scene.walls and scene.sky_color is not None
    (xmin, ymin), (xmax, ymax) = scene.bounds
    gx, gy = np.meshgrid(np.linspace(xmin, xmax, 60), np.linspace(ymin, ymax, 60))
    grid = np.stack([gx.ravel(), gy.ravel()], 1)
    without = lambda *names: replace(scene, meshes=tuple(  # noqa: E731
        p for p in scene.meshes if p.name not in names))
    free = clearances(scene, grid)
    assert np.array_equal(free, clearances(without("crowns", "hills", "ground"), grid))
    for blocking in ("trunks", "rocks_and_bushes"):
        opened = clearances(without(blocking), grid)
        assert np.all(opened >= free) and np.any(opened > free + 0.1), blocking
    # the middle of every trunk inside the bounds is blocked
    trunk = parts["trunks"]
    rings = trunk.vertices[np.abs(trunk.vertices[:, 2]) < 1e-9]
    inside = rings[(rings[:, 0] > xmin) & (rings[:, 0] < xmax) & (rings[:, 1] > ymin)
                   & (rings[:, 1] < ymax)]
    assert len(inside)
    for x, y, _ in inside[::10]:
        near = inside[np.hypot(inside[:, 0] - x, inside[:, 1] - y) < 0.3]
        assert clearance(scene, near[:, :2].mean(axis=0)) == 0.0


@pytest.mark.parametrize("name", PROCEDURAL)
def test_env_checker_and_seeded_episodes(name, make_env):
    env = make_env(scene=name, renderer="raycast")
    check_env(env.unwrapped, skip_render_check=True)
    first, _ = env.reset(seed=5)
    other, _ = env.reset(seed=6)
    again, _ = env.reset(seed=5)
    assert np.array_equal(first["panorama"], again["panorama"])
    assert not np.array_equal(first["panorama"], other["panorama"])


@pytest.mark.parametrize("name", PROCEDURAL)
@pytest.mark.parametrize("renderer", ["raycast", "tiny"])
def test_oracle_homes_in_procedural_worlds(name, renderer, make_env, controller_for):
    env = make_env(scene=name, renderer=renderer, success_on="stop", max_episode_steps=400)
    oracle = controller_for("oracle", env)
    for seed in (0, 1):
        result = rollout(env, oracle, seed=seed)
        assert result.info["is_success"], (seed, result.info["distance_to_goal"])
        assert math.dist(result.info["pose"][:2], result.info["home_pose"][:2]) < 0.15


def test_the_nature_generator_declares_the_solids_trimesh_would_find():
    """random_nature gives each part's closed solids (MeshPart.solid_faces) instead of
    letting trimesh search for them on every reset: the same face sets."""
    from homing_gym.scenes import scene_factory
    from homing_gym.scenes.mesh_part import MeshPart

    for seed in range(3):
        for part in scene_factory("random_nature").build(np.random.default_rng(seed)).meshes:
            found = MeshPart(part.vertices, part.faces, part.face_colors, name=part.name).solids
            assert (sorted(tuple(f) for f in part.solids)
                    == sorted(tuple(f) for f in found)), (seed, part.name)


def test_solid_faces_out_of_range_are_refused():
    from homing_gym.scenes.mesh_part import MeshPart

    tri = dict(vertices=np.eye(3), faces=[[0, 1, 2]], face_colors=[[1.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="solid_faces"):
        MeshPart(**tri, solid_faces=([0, 1],))
    with pytest.raises(ValueError, match="solid_faces"):
        MeshPart(**tri, solid_faces=([],))


def test_episodes_per_world_keeps_a_world_for_that_many_unseeded_resets(make_env):
    env = make_env(scene="random_rooms", episodes_per_world=3, panorama_shape=(8, 32))
    env.reset(seed=5)
    worlds = [env.unwrapped.scene]
    homes = [env.unwrapped.episode.goals[-1]]
    for _ in range(5):
        env.reset()
        worlds.append(env.unwrapped.scene)
        homes.append(env.unwrapped.episode.goals[-1])
    assert worlds[0] is worlds[1] is worlds[2]
    assert worlds[3] is worlds[4] is worlds[5] and worlds[3] != worlds[0]
    assert len({tuple(np.round(h, 6)) for h in homes[:3]}) == 3    # new episodes in it
    env.reset(seed=5)                                    # a seeded reset: the seed's world
    assert _signature(env.unwrapped.scene) == _signature(worlds[0])
    with pytest.raises(ValueError, match="episodes_per_world"):
        make_env(scene="random_rooms", episodes_per_world=0)
