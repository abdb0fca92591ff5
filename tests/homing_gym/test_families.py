"""The world families' registry: names, kinds, roles, seeded worlds with their own
appearance, and the errors a user meets."""

import dataclasses

import gymnasium as gym
import numpy as np
import pytest

import homing_gym  # noqa: F401
from homing_gym.scenes import SceneFactory, available_scenes, scene_factory
from homing_gym.scenes.base import Scene
from homing_gym.scenes.families import FAMILIES, KINDS, families_in, family

NEW = [name for name in FAMILIES if not name.startswith("random_")]


def test_at_least_ten_families_of_every_kind_each_a_scene_name():
    assert len(FAMILIES) >= 10
    assert {f.kind for f in FAMILIES.values()} == set(KINDS)
    assert set(FAMILIES) <= set(available_scenes())
    assert all(scene_factory(name).randomised for name in FAMILIES)


def test_test_families_are_natural_built_and_indoor_and_never_train():
    test = families_in("test")
    assert {family(name).kind for name in test} >= {"natural", "built", "indoor"}
    assert not set(test) & set(families_in("train")) and families_in("validation")


def _same_world(a: Scene, b: Scene) -> bool:
    """Equal scenes, mesh parts compared by their names and arrays, textures included
    (MeshPart compares by identity)."""
    plain = dataclasses.replace(a, meshes=()) == dataclasses.replace(b, meshes=())
    return plain and len(a.meshes) == len(b.meshes) and all(
        m.name == n.name and np.array_equal(getattr(m, k), getattr(n, k))
        for m, n in zip(a.meshes, b.meshes)
        for k in ("vertices", "faces", "face_colors", "uvs", "texture"))


@pytest.mark.parametrize("name", NEW)
def test_a_family_world_is_its_seeds_with_its_own_appearance(name):
    build = family(name).build
    a, b = build(np.random.default_rng(5)), build(np.random.default_rng(5))
    other = build(np.random.default_rng(6))
    assert isinstance(a, Scene) and a.name == name
    assert _same_world(a, b) and not _same_world(a, other)
    assert a.appearance != other.appearance and a.bounds != other.bounds
    assert a.appearance.sky_zenith is not None and a.appearance.camera_height is not None


@pytest.mark.parametrize("name", NEW)
def test_localhoming_draws_episodes_0_3_to_2_m_in_every_family(name):
    env = gym.make("homing_gym/LocalHoming-v0", scene=name, start_distance=(0.3, 2.0),
                   panorama_shape=(16, 64))
    for seed in range(3):
        _, info = env.reset(seed=seed)
        assert 0.3 <= np.hypot(*(info["home_pose"][:2] - info["start_pose"][:2])) <= 2.0
        assert env.unwrapped.scene.name == name
    env.close()


def test_unknown_family_names_list_the_known_ones():
    with pytest.raises(ValueError, match="unknown world family 'forst'.*'forest'"):
        family("forst")
    with pytest.raises(ValueError, match="unknown scene 'forst'.*'forest'"):
        gym.make("homing_gym/LocalHoming-v0", scene="forst")
    with pytest.raises(ValueError, match="unknown role 'tests'"):
        families_in("tests")


def test_a_world_without_room_for_an_episode_names_its_seed():
    strip = Scene(name="strip", bounds=((-0.2, -1.5), (0.2, 1.5)), fence=True)
    env = gym.make("homing_gym/LocalHoming-v0",
                   scene=SceneFactory(build=lambda rng: strip, randomised=True))
    with pytest.raises(ValueError, match=r"'strip'.*reset\(seed=17\)"):
        env.reset(seed=17)
    env.close()
