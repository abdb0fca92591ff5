"""The narrow contracts of the env core: task context, observation table, info, validation."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from homing_gym import HomingEnv
from homing_gym.observations import ObservationKey, constant_key
from homing_gym.tasks import Episode, Task
from homing_gym.tasks.context import TaskContext
from homing_gym.validation import require_positive


class WalkEast(Task):
    """A toy task: start at (0, 0) facing east, succeed past x = 0.3 m. Adds two keys."""

    def __init__(self):
        self.seen: list[TaskContext] = []
        self.steps = 0

    def sample_episode(self, scene, rng):
        return Episode(home=np.array([0.5, 0.0, 0.0]), start=np.array([0.0, 0.0, 0.0]))

    def on_reset(self, ctx):
        self.seen.append(ctx)
        self.steps = 0

    def step_outcome(self, ctx, collision, stopped):
        self.steps += 1
        done = ctx.pose()[0] > 0.3
        return {"progress": 0.0}, done, done

    def observation_keys(self):
        return {"steps": constant_key(spaces.Box(0, 10_000, (1,), np.int64),
                                      lambda: np.array([self.steps], np.int64)),
                "mean_grey": ObservationKey(
                    lambda config: spaces.Box(0.0, 255.0, (), np.float32),
                    lambda sight: np.asarray(sight.panorama.mean(), np.float32))}


def test_a_task_runs_through_its_context_only():
    task = WalkEast()
    env = HomingEnv(task, "arena", obs_keys=("panorama", "steps", "mean_grey"),
                    panorama_shape=(16, 64))
    obs, info = env.reset(seed=0)
    ctx = task.seen[-1]
    assert isinstance(ctx, TaskContext)
    for forbidden in ("sim", "step", "camera_render", "odometry", "reset"):
        assert not hasattr(ctx, forbidden)
    assert set(obs) == {"panorama", "steps", "mean_grey"}
    assert obs["mean_grey"] == pytest.approx(obs["panorama"].mean())
    done, n = False, 0
    while not done and n < 100:
        obs, _, done, _, info = env.step(np.array([1.0, 0.0], np.float32))
        n += 1
    assert done and info["is_success"] and obs["steps"][0] == n
    assert env.observation_space.contains(obs)
    env.close()


def test_info_carries_home_and_start_as_reset_options_set_them():
    env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(16, 64))
    home, start = [0.2, -0.3, 1.0], [-0.7, 0.3, -2.0]     # start clear of the cylinders
    _, info = env.reset(seed=3, options={"home": home, "start": start})
    np.testing.assert_allclose(info["home_pose"], home, atol=1e-6)
    np.testing.assert_allclose(info["start_pose"], start, atol=1e-4)
    _, _, _, _, step_info = env.step(env.action_space.sample())
    np.testing.assert_array_equal(step_info["home_pose"], info["home_pose"])
    np.testing.assert_array_equal(step_info["start_pose"], info["start_pose"])
    env.close()


@pytest.mark.parametrize("bad", [True, "1", float("nan"), float("inf"), 0, -1, None])
def test_require_positive_rejects_what_is_not_a_positive_number(bad):
    with pytest.raises(ValueError, match=r"speed must be a positive number of m/s, got"):
        require_positive("speed", bad, "m/s")


def test_require_positive_accepts_positive_numbers():
    assert require_positive("x", 0.5) == 0.5
    assert require_positive("x", np.float32(2.0)) == 2.0
    assert isinstance(require_positive("x", 3), float)
