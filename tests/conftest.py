"""Shared fixtures: small, fast envs."""

import gymnasium as gym
import pytest

import homing_gym

gym.register_envs(homing_gym)

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
