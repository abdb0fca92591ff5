"""Shared fixtures: envs that close themselves, controllers prepared as the harness does."""

import math

import gymnasium as gym
import pytest

import homing_baselines
import homing_gym
from homing_train.harness.rollout import prepare_policy

gym.register_envs(homing_gym)


def _free_start(env, home, distance, angle, heading, margin=0.25):
    """The first start ``distance`` m from ``home`` at ``angle`` or counter-clockwise
    beyond it (0.1 rad steps) with ``margin`` m of clearance: a valid start pose."""
    from homing_gym.scenes.base import clearance

    for k in range(63):
        a = angle + 0.1 * k
        xy = (home[0] + distance * math.cos(a), home[1] + distance * math.sin(a))
        if clearance(env.unwrapped.scene, xy) >= margin:
            return (*xy, heading)
    raise AssertionError("no free start")


@pytest.fixture(autouse=True, scope="session")
def sb3_log_folder(tmp_path_factory):
    """SB3's default logger (a ``learn()`` without ``set_logger``) writes into pytest's
    temporary folder instead of leaving an ``SB3-<date>`` folder in the system's."""
    mp = pytest.MonkeyPatch()
    mp.setenv("SB3_LOGDIR", str(tmp_path_factory.mktemp("sb3-logs")))
    yield
    mp.undo()


@pytest.fixture
def free_start():
    """The helper :func:`_free_start` (a valid start pose around a home)."""
    return _free_start


def pytest_addoption(parser):
    parser.addoption("--run-slow", action="store_true",
                     help="also run the tests marked slow (CI and the README command do)")


def pytest_collection_modifyitems(config, items):
    if config.getoption("--run-slow"):
        return
    skip = pytest.mark.skip(reason="slow: run with --run-slow")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)

ENV_ID = "homing_gym/LocalHoming-v0"


@pytest.fixture
def make_env():
    """Factory that closes every env it made at the end of the test."""
    made = []

    def factory(env_id: str = ENV_ID, **kwargs):
        env = gym.make(env_id, **kwargs)
        made.append(env)
        return env

    yield factory
    for env in made:
        env.close()


@pytest.fixture
def controller_for():
    """Factory: ``controller_for(name, env, **params)``, a registered controller with
    parameters, prepared for ``env`` as the harness prepares it."""

    def factory(name: str, env, **params):
        controller = homing_baselines.make(name, **params)
        prepare_policy(controller, env)
        return controller

    return factory
