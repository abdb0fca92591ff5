"""Envs grouped into fewer subprocesses: the same episodes as one process, indices mapped."""

import numpy as np
import pytest
from gymnasium.wrappers import RecordEpisodeStatistics
from stable_baselines3.common.monitor import Monitor

from homing_train.learning.train import TrainConfig, make_vec

KWARGS = {"scene": ["random_rooms", "random_nature"], "panorama_shape": [8, 32],
          "action_type": "discrete", "max_episode_steps": 6}


def _run(vec: str, workers: int | None, actions: np.ndarray):
    config = TrainConfig("homing_gym/LocalHoming-v0", n_envs=5, vec=vec, workers=workers,
                         env_kwargs=KWARGS)
    env = make_vec(config, 5, seed=3)
    try:
        frames = [env.reset()]
        rewards, dones, terminal = [], [], []
        for a in actions:
            obs, r, d, infos = env.step(a)
            frames.append(obs)
            rewards.append(r)
            dones.append(d)
            terminal.append([info["terminal_observation"]["panorama"].sum()
                             if "terminal_observation" in info else -1 for info in infos])
        return frames, np.array(rewards), np.array(dones), np.array(terminal)
    finally:
        env.close()


def test_grouped_workers_give_the_episodes_of_one_process():
    """5 envs in 2 workers (3 + 2) against the same 5 in one process: identical
    observations, rewards, episode ends and terminal observations, resets included."""
    actions = np.random.default_rng(0).integers(0, 4, (14, 5))   # stops end episodes early
    frames_g, rewards_g, dones_g, terminal_g = _run("subproc", 2, actions)
    frames_d, rewards_d, dones_d, terminal_d = _run("dummy", None, actions)
    assert dones_d.any() and (terminal_d >= 0).any()             # resets were exercised
    for a, b in zip(frames_g, frames_d):
        for key in b:
            np.testing.assert_array_equal(a[key], b[key])
    np.testing.assert_array_equal(rewards_g, rewards_d)
    np.testing.assert_array_equal(dones_g, dones_d)
    np.testing.assert_array_equal(terminal_g, terminal_d)


def test_methods_and_attributes_reach_the_envs_asked_for():
    config = TrainConfig("homing_gym/LocalHoming-v0", n_envs=5, vec="subproc", workers=2,
                         env_kwargs=KWARGS)
    env = make_vec(config, 5, seed=0)
    try:
        env.reset()
        venv = env.venv
        assert venv.groups in ([(0, 2), (2, 5)], [(0, 3), (3, 5)])
        names = [s.name for s in venv.get_attr("scene")]
        assert names == ["random_rooms", "random_nature"] * 2 + ["random_rooms"]
        assert [s.name for s in venv.get_attr("scene", indices=[4, 1])] == ["random_rooms",
                                                                          "random_nature"]
        before = [t.start_distance for t in venv.get_attr("task")]
        venv.env_method("set_start_distance", (0.2, 0.3), indices=[3])
        after = [t.start_distance for t in venv.get_attr("task")]
        assert after[3] == (0.2, 0.3) and after[:3] + after[4:] == before[:3] + before[4:]
        assert venv.env_is_wrapped(Monitor) == [True] * 5
        assert venv.env_is_wrapped(RecordEpisodeStatistics, indices=[0, 4]) == [False] * 2
    finally:
        env.close()


def test_bad_worker_counts_are_refused():
    for bad in (0, 6, 2.5):
        with pytest.raises(ValueError, match="workers must be an integer from 1 to n_envs"):
            TrainConfig("homing_gym/LocalHoming-v0", n_envs=5, workers=bad)
