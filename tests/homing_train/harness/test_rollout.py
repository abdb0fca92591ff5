"""The one episode loop (homing_train.harness.rollout)."""

import numpy as np
import pytest

from homing_train.harness.rollout import rollout


@pytest.fixture
def env(make_env):
    return make_env(panorama_shape=(16, 64), max_episode_steps=12)


def test_poses_come_from_info_and_match_the_env_trajectory(env, controller_for):
    policy = controller_for("random", env)
    run = rollout(env, policy, seed=4)
    assert run.truncated or run.terminated
    assert run.poses.shape == (run.steps + 1, 3)
    np.testing.assert_array_equal(run.poses[:, :2], np.asarray(env.unwrapped.trajectory))
    np.testing.assert_array_equal(run.poses[0], run.reset_info["start_pose"])


def test_the_hook_sees_every_step_in_order_and_can_stop_early(env, controller_for):
    policy = controller_for("random", env)
    seen = []

    def hook(t, obs, action, info):
        seen.append((t, info["pose"].copy()))
        return t == 5

    run = rollout(env, policy, seed=4, on_step=hook)
    assert [t for t, _ in seen] == list(range(6))
    assert run.stopped and run.steps == 5 and not (run.terminated or run.truncated)
    np.testing.assert_array_equal(seen[-1][1], run.poses[-1])   # pose before step 5


def test_max_steps_and_reset_options(env, controller_for):
    policy = controller_for("random", env)
    run = rollout(env, policy, seed=1, options={"start": [0.0, 0.0, 0.0]}, max_steps=3)
    assert run.steps == 3 and not run.stopped
    np.testing.assert_allclose(run.poses[0][:2], [0.0, 0.0], atol=1e-4)


def test_the_same_seed_gives_the_same_episode(env, controller_for):
    policy = controller_for("random", env)
    a, b = rollout(env, policy, seed=7), rollout(env, policy, seed=7)
    np.testing.assert_array_equal(a.poses, b.poses)
