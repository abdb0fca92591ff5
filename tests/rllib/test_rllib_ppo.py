"""RLlib PPO on the homing envs (homing_train.learning.rllib_ppo).

The observation wrapper and the settings checks run everywhere. The training test needs
``ray[rllib]``, which pins a gymnasium older than the main environment's: ``.ci/rllib``
runs this folder in a virtual environment of its own (.venv-rllib); elsewhere that test
is skipped."""

import math

import numpy as np
import pytest

from homing_train.learning.rllib_ppo import RllibSettings, StackedGoalPanorama, summarize

SMALL = {"panorama_shape": [16, 64], "max_episode_steps": 20}
NO_RLLIB = "ray[rllib] is not installed here: run .ci/rllib"


def test_stacked_goal_panorama_is_panorama_then_goal_scaled_to_one(make_env):
    env = make_env(**SMALL)
    raw, _ = env.reset(seed=0)
    wrapped = StackedGoalPanorama(env)
    stacked = wrapped.observation(raw)
    assert stacked.shape == (16, 64, 6) and stacked.dtype == np.float32
    assert wrapped.observation_space.contains(stacked)
    np.testing.assert_array_equal(np.rint(stacked[..., :3] * 255), raw["panorama"])
    np.testing.assert_array_equal(np.rint(stacked[..., 3:] * 255), raw["goal"])
    assert not np.array_equal(raw["panorama"], raw["goal"])  # the order is visible
    obs, _ = wrapped.reset(seed=1)
    assert wrapped.observation_space.contains(obs)


def test_stacked_goal_panorama_refuses_other_observation_keys(make_env):
    env = make_env(obs_keys=("panorama", "goal", "odometry"), **SMALL)
    with pytest.raises(ValueError, match="exactly the keys"):
        StackedGoalPanorama(env)


@pytest.mark.parametrize("kwargs, message", [
    ({"num_env_runners": -1}, "num_env_runners"),
    ({"num_envs_per_env_runner": 0}, "num_envs_per_env_runner"),
    ({"train_batch_size": 1}, "train_batch_size"),
    ({"hyperparams": {"target_kl": 0.01}}, "no RLlib counterpart"),
])
def test_settings_refuse_bad_values(kwargs, message):
    with pytest.raises(ValueError, match=message):
        RllibSettings(**kwargs)


def test_config_refuses_a_minibatch_larger_than_an_iteration():
    pytest.importorskip("ray.rllib.algorithms.ppo", reason=NO_RLLIB)
    from homing_train.learning.rllib_ppo import ppo_config

    with pytest.raises(ValueError, match="exceeds the 64 env steps"):
        ppo_config(RllibSettings(train_batch_size=64, hyperparams={"batch_size": 128}))


@pytest.fixture
def local_ray():
    ray = pytest.importorskip("ray")
    pytest.importorskip("ray.rllib.algorithms.ppo", reason=NO_RLLIB)
    ray.init(num_cpus=2, include_dashboard=False)
    yield
    ray.shutdown()


def test_one_ppo_iteration_with_two_env_runners_learns_from_sampled_episodes(local_ray):
    from homing_train.learning.rllib_ppo import ppo_config

    settings = RllibSettings(env_kwargs=SMALL, num_env_runners=2, train_batch_size=128,
                             hyperparams={"batch_size": 64, "n_epochs": 2})
    algo = ppo_config(settings).build_algo()
    try:
        assert algo.get_module().observation_space.shape == (16, 64, 6)
        before = algo.learner_group.get_weights()["default_policy"]
        s = summarize(algo.train())
        after = algo.learner_group.get_weights()["default_policy"]
    finally:
        algo.stop()
    assert s.env_steps >= 128 and s.env_steps_lifetime == s.env_steps
    # 20-step episodes: each of the 2 runners finishes at least 64 // 20 of them
    assert s.episodes >= 2 * (64 // 20)
    assert math.isfinite(s.episode_return_mean)
    assert all(math.isfinite(v) for v in (s.policy_loss, s.vf_loss, s.entropy))
    changed = [k for k in before if not np.array_equal(before[k], after[k])]
    assert changed, "the learner's update left every weight unchanged"
