"""The env core's arguments live in one validated frozen config, EnvConfig; its field
table is what the env cards show, and every env id judges success by the stop rule
unless asked otherwise."""

import dataclasses
import inspect
import math

import gymnasium as gym
import numpy as np
import pytest

import homing_gym
from homing_gym.config import EnvConfig, Range, field_table
from homing_gym.env import HomingEnv
from homing_gym.envcard import arguments, env_card
from homing_gym.tasks import LocalHomingTask


def _outside(rule: Range) -> list:
    """Values just outside each end of ``rule``."""
    step = 1 if rule.integer else 1e-6
    return [rule.low if rule.low_open else rule.low - step,
            rule.high if rule.high_open else rule.high + step]


RANGES = [(f.name, f.metadata["allowed"]) for f in dataclasses.fields(EnvConfig)
          if isinstance(f.metadata["allowed"], Range)]


@pytest.mark.parametrize("name, rule", RANGES, ids=[name for name, _ in RANGES])
def test_the_documented_range_is_the_enforced_one(name, rule):
    for value in _outside(rule):
        with pytest.raises(ValueError, match=name):
            EnvConfig(**{name: value})
    if name not in ("physics_substeps", "control_period"):   # their ends: each other's
        for value, closed in ((rule.low, not rule.low_open), (rule.high, not rule.high_open)):
            if closed:
                assert getattr(EnvConfig(**{name: value}), name) == value


def test_the_config_is_frozen_hashable_and_normalised():
    config = EnvConfig(panorama_shape=[16, 64], obs_keys=["panorama"], sky_color=[0, 0, 1],
                       physics_substeps=np.int64(12), control_period=np.float32(0.1))
    assert config.panorama_shape == (16, 64) and config.obs_keys == ("panorama",)
    assert config.sky_color == (0, 0, 1) and type(config.physics_substeps) is int
    assert hash(config) == hash(dataclasses.replace(config))
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.max_speed = 1.0
    assert config.camera().panorama_shape == (16, 64)
    assert config.robot().max_speed == 0.3


@pytest.mark.parametrize("kwargs, words", [
    ({"supersampling": 3, "renderer": "tiny"}, ["supersampling", "raycast", "tiny"]),
    ({"shadows": True, "renderer": "egl"}, ["shadows", "raycast"]),
    ({"control_period": 0.1, "physics_substeps": 1}, ["physics steps", "1/60"]),
    ({"drive": "synchro", "action_type": "discrete"}, ["synchro", "continuous"]),
    ({"max_speed": 5.0}, ["max_speed", "rad/s"]),
    ({"n_views": 6.0}, ["n_views", "6.0"]),
])
def test_arguments_that_depend_on_each_other_are_checked_together(kwargs, words):
    with pytest.raises(ValueError) as err:
        EnvConfig(**kwargs)
    for word in words:
        assert word in str(err.value)


def test_homing_env_names_an_unknown_argument_and_lists_the_known():
    with pytest.raises(ValueError, match=r"\['bogus'\].*camera_height"):
        HomingEnv(LocalHomingTask(), bogus=1)


def test_an_env_reads_its_settings_from_its_config(make_env):
    env = make_env(control_period=0.2, physics_substeps=24, stop_threshold=0.1)
    u = env.unwrapped
    assert u.config.control_period == u.control_period == 0.2
    assert u.sim.time_step == pytest.approx(0.2 / 24)
    assert u.config.robot() == u.robot_config


@pytest.mark.parametrize("env_id", homing_gym.ENV_IDS)
def test_the_card_table_shows_the_defaults_in_force(env_id):
    module, name = gym.spec(env_id).entry_point.split(":")
    cls = getattr(__import__(module, fromlist=[name]), name)
    params = inspect.signature(cls.__init__).parameters
    core = {row.name: row.default for row in field_table()}
    rows = arguments(cls)
    assert {r.name for r in rows} >= set(core) | {"scene", "success_on", "reward"}
    for row in rows:
        expected = params[row.name].default if row.name in params else core[row.name]
        assert row.default == expected, row.name
    card = env_card(env_id)
    assert "| `success_on` | `str` | `'stop'` |" in card
    assert f"| `control_period` | `float` | `{EnvConfig.control_period:g}` |" in card
    assert math.isclose(dict((r.name, r.default) for r in rows)["vfov_deg"], 60)


def test_work_locations_card_shows_its_own_panorama_default():
    from homing_gym.envs import WorkLocationsEnv
    assert {r.name: r.default for r in arguments(WorkLocationsEnv)}["panorama_shape"] == (64, 512)


def test_local_homing_ends_on_stop_by_default_and_on_reaching_when_asked(make_env):
    home, start = (0.0, 0.0, 0.0), (0.05, 0.0, 0.0)          # start within the radius
    env = make_env()
    env.reset(seed=0, options={"home": home, "start": start})
    _, _, terminated, _, info = env.step(np.array([0.5, 0.0], np.float32))
    assert not terminated and info["distance_to_goal"] < 0.15   # inside, not yet stopped
    _, _, terminated, _, info = env.step(np.array([0.0, 0.0], np.float32))
    assert terminated and info["is_success"]
    reach = make_env(success_on="reach")
    reach.reset(seed=0, options={"home": home, "start": start})
    _, _, terminated, _, info = reach.step(np.array([0.5, 0.0], np.float32))
    assert terminated and info["is_success"]
