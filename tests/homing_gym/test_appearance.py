"""A world's appearance (sky gradient, light, shadows, camera height): what the camera
sees under it, and which of the env's arguments override it."""

import dataclasses
import math

import gymnasium as gym
import numpy as np
import pytest

import homing_gym  # noqa: F401
from homing_gym.render.panorama import CameraConfig, Lighting
from homing_gym.scenes.appearance import CAMERA_HEIGHTS, Appearance, random_appearance
from homing_gym.scenes.arena import arena_scene
from homing_gym.scenes.base import Landmark, Scene

HORIZON, ZENITH = (0.9, 0.6, 0.4), (0.1, 0.2, 0.8)
SHAPE, VFOV = (40, 128), 90.0


def _open_world(appearance: Appearance) -> Scene:
    """A fenced floor with one post far off: almost all sky above the horizon."""
    return Scene(name="open", bounds=((-3, -3), (3, 3)), fence=True,
                 landmarks=(Landmark((2.8, 2.8), radius=0.05, height=0.2),),
                 sky_color=HORIZON, appearance=appearance)


def _env(scene: Scene, **kwargs):
    return gym.make("homing_gym/LocalHoming-v0", scene=scene, panorama_shape=SHAPE,
                    vfov_deg=VFOV, **kwargs)


def test_sky_blends_from_horizon_to_zenith_linearly_in_elevation():
    env = _env(_open_world(Appearance(sky_zenith=ZENITH)))
    obs, _ = env.reset(seed=0)
    H = SHAPE[0]
    column = obs["panorama"][:H // 2, 5].astype(float)      # above the horizon, sky only
    elevation = math.radians(VFOV) / 2 - math.radians(VFOV) * (np.arange(H // 2) + 0.5) / H
    up = elevation[:, None] / (math.pi / 2)
    expected = 255 * (np.array(HORIZON) * (1 - up) + np.array(ZENITH) * up)
    np.testing.assert_allclose(column, expected, atol=1.0)
    env.close()


def test_the_envs_sky_color_makes_the_sky_uniform():
    env = _env(_open_world(Appearance(sky_zenith=ZENITH)), sky_color=(0.2, 0.4, 0.6))
    obs, _ = env.reset(seed=0)
    np.testing.assert_array_equal(obs["panorama"][0, 5], np.round(255 * np.array([0.2, 0.4, 0.6])))
    np.testing.assert_array_equal(obs["panorama"][0, 5], obs["panorama"][SHAPE[0] // 2 - 1, 5])
    env.close()


def _arena(**appearance) -> Scene:
    return dataclasses.replace(arena_scene(), appearance=Appearance(**appearance))


def test_the_worlds_light_shades_the_run_and_the_snapshot():
    light = dict(light_direction=(1.0, -0.5, 0.4), ambient=0.3, diffuse=0.8)
    env = _env(_arena(**light))
    obs, _ = env.reset(seed=1)
    u = env.unwrapped
    camera = CameraConfig(panorama_shape=SHAPE, vfov=math.radians(VFOV))
    lit = u.sim.caster.panorama(u.pose, 0.30, camera, Lighting(**{
        "direction": light["light_direction"], "ambient": 0.3, "diffuse": 0.8}))
    np.testing.assert_array_equal(obs["panorama"], lit)
    plain = u.sim.caster.panorama(u.pose, 0.30, camera)
    assert np.abs(obs["panorama"].astype(int) - plain).max() > 20     # not the default light
    goal = u.sim.caster.panorama(u.episode.home, 0.30, camera, u._world_lighting)
    np.testing.assert_array_equal(obs["goal"], goal)
    env.close()


def test_the_worlds_camera_height_unless_the_env_gives_one():
    world = _arena(camera_height=0.05)
    env = _env(world)
    obs, _ = env.reset(seed=2)
    u = env.unwrapped
    assert u.robot_config.camera_height == u.camera.camera_height == 0.05
    camera = CameraConfig(panorama_shape=SHAPE, vfov=math.radians(VFOV))
    np.testing.assert_array_equal(obs["panorama"],
                                  u.sim.caster.panorama(u.pose, 0.05, camera))
    env.close()
    mine = _env(world, camera_height=0.2)
    mine.reset(seed=2)
    assert mine.unwrapped.camera.camera_height == 0.2
    mine.close()


def test_a_new_world_brings_its_own_camera_height():
    worlds = iter([_arena(camera_height=0.05), _arena(camera_height=0.4)])
    from homing_gym.scenes import SceneFactory
    env = _env(SceneFactory(build=lambda rng: next(worlds, _arena(camera_height=0.1)),
                            randomised=True))
    heights = []
    for seed in range(2):
        env.reset(seed=seed)
        heights.append(env.unwrapped.camera.camera_height)
    assert heights == [0.4, 0.1]      # the first world was the constructor's
    env.close()


def test_a_camera_height_range_draws_each_episodes_height_and_renders_from_it():
    env = _env(_arena(camera_height=0.05), camera_height=(0.1, 0.4))   # the env's wins
    u = env.unwrapped
    camera = CameraConfig(panorama_shape=SHAPE, vfov=math.radians(VFOV))
    heights = []
    for seed in range(8):
        obs, _ = env.reset(seed=seed)
        h = u.camera.camera_height
        assert u.robot_config.camera_height == h and 0.1 <= h <= 0.4
        np.testing.assert_array_equal(obs["panorama"], u.sim.caster.panorama(u.pose, h, camera))
        np.testing.assert_array_equal(obs["goal"], u.sim.caster.panorama(u.episode.home, h,
                                                                         camera))
        heights.append(h)
    assert len(set(heights)) == 8 and max(heights) - min(heights) > 0.1
    again, _ = env.reset(seed=3)                  # a seed gives its height and its episode
    assert u.camera.camera_height == heights[3]
    env.close()


@pytest.mark.parametrize("value, words", [
    ((0.4, 0.1), ["camera_height", "(0.4, 0.1)", "low <= high"]),
    ((0.1, 9.0), ["camera_height", "9", "[0.005, 5]"]),
    ((0.1,), ["camera_height", "pair (low, high)"]),
])
def test_a_bad_camera_height_range_is_refused_by_name(value, words):
    with pytest.raises(ValueError) as error:
        _env(_arena(), camera_height=value)
    assert all(w in str(error.value) for w in words), str(error.value)


@pytest.mark.parametrize("env_shadows, expected", [(None, True), (False, False)])
def test_the_worlds_shadows_unless_the_env_says(env_shadows, expected):
    env = _env(_arena(shadows=True), shadows=env_shadows)
    env.reset(seed=0)
    assert env.unwrapped.sim.caster.shadows is expected
    env.close()


@pytest.mark.parametrize("fields, words", [
    ({"sky_zenith": (2, 0, 0)}, ["sky_zenith", "2"]),
    ({"sky_zenith": "blue"}, ["sky_zenith", "blue"]),
    ({"light_direction": (0, 0, 0)}, ["light_direction", "not all zero"]),
    ({"light_direction": (1, float("nan"), 0)}, ["light_direction"]),
    ({"ambient": -0.1}, ["ambient", "-0.1"]),
    ({"shadows": "yes"}, ["shadows", "yes"]),
    ({"camera_height": 0.0}, ["camera_height", "metres"]),
])
def test_bad_appearance_is_refused_by_name(fields, words):
    with pytest.raises(ValueError) as error:
        Appearance(**fields)
    assert all(w in str(error.value) for w in words)


def test_random_appearance_is_seeded_and_in_range():
    draws = [random_appearance(np.random.default_rng(s), outdoor=s % 2 == 0) for s in range(40)]
    assert draws[:4] == [random_appearance(np.random.default_rng(s), outdoor=s % 2 == 0)
                         for s in range(4)]
    heights = [a.camera_height for _, a in draws]
    assert CAMERA_HEIGHTS[0] <= min(heights) and max(heights) <= CAMERA_HEIGHTS[1]
    assert max(heights) - min(heights) > 0.3
    shadows = [a.shadows for _, a in draws]
    assert 5 < sum(shadows) < 35
    up = [a.light_direction[2] for _, a in draws]
    assert min(up) > math.sin(math.radians(14))
