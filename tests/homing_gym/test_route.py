"""RouteFollowing-v0: the route's geometry, goal switching, per-target errors, both modes."""

import numpy as np
import pytest

from homing_gym.scenes import Scene, square_walls
from homing_gym import FOOT

ROUTE = "homing_gym/RouteFollowing-v0"
FORWARD = np.array([1.0, 0.0], np.float32)


def test_route_layout_follows_the_paper(make_env):
    env = make_env(ROUTE)
    obs, info = env.reset(seed=4)
    goals = np.array(env.unwrapped.episode.goals)
    assert len(goals) == 17
    assert np.allclose(np.hypot(*np.diff(goals[:, :2], axis=0).T), FOOT)
    first = goals[0]
    assert np.hypot(*(info["pose"][:2] - first[:2])) == pytest.approx(FOOT, abs=0.08)
    assert info["target_index"] == 0 and info["target_errors"] == []
    assert np.allclose(info["goal_pose"], first)


def test_driving_the_route_reaches_every_target_in_order(make_env):
    env = make_env(ROUTE, panorama_shape=(16, 64))
    x0, y0, _ = env.unwrapped.scene.metadata["route_origin"]
    obs, info = env.reset(seed=0, options={"start": (x0 - FOOT, y0, 0.0)})
    goals_seen, indices = [obs["goal"]], [0]
    terminated = truncated = False
    while not (terminated or truncated):
        obs, reward, terminated, truncated, info = env.step(FORWARD)
        if info["target_index"] != indices[-1]:
            indices.append(info["target_index"])
            goals_seen.append(obs["goal"])
            assert info["rewards"]["waypoint"] == 1.0
    assert terminated and info["is_success"]
    assert indices == list(range(17))
    assert len(info["target_errors"]) == 17 and max(info["target_errors"]) < 0.1
    assert not any(np.array_equal(a, b) for a, b in zip(goals_seen, goals_seen[1:]))


def test_stop_mode_records_stop_errors_and_advances(make_env):
    env = make_env(ROUTE, panorama_shape=(16, 64), success_on="stop", action_type="discrete",
                   n_targets=3)
    x0, y0, _ = env.unwrapped.scene.metadata["route_origin"]
    env.reset(seed=0, options={"start": (x0 - FOOT, y0, 0.0)})
    _, _, terminated, _, info = env.step(3)                      # stop at once: 1 ft short
    assert not terminated and info["target_index"] == 1
    assert info["target_errors"][0] == pytest.approx(FOOT, abs=0.01)
    _, _, terminated, _, info = env.step(3)
    assert not terminated and info["target_index"] == 2
    assert info["target_errors"][1] == pytest.approx(2 * FOOT, abs=0.01)
    _, reward, terminated, _, info = env.step(3)                 # stop for the last target
    assert terminated and not info["is_success"]
    assert info["target_errors"][2] == pytest.approx(3 * FOOT, abs=0.01)
    assert info["rewards"]["success"] == 0.0


def test_route_needs_a_scene_with_a_route():
    import gymnasium as gym

    plain = Scene("plain", ((-1, -1), (1, 1)), walls=square_walls(2.0))
    with pytest.raises(ValueError, match="route"):
        gym.make(ROUTE, scene=plain)
    with pytest.raises(ValueError, match="do not fit"):
        gym.make(ROUTE, n_targets=40)


def test_lighting_change_alters_the_run_but_not_the_snapshots(make_env):
    plain = make_env(ROUTE)
    lit = make_env(ROUTE, lighting_change=1.0)
    a, _ = plain.reset(seed=3)
    b, _ = lit.reset(seed=3)
    c, _ = lit.reset(seed=3)
    assert np.array_equal(a["goal"], b["goal"])
    assert np.abs(a["panorama"].astype(int) - b["panorama"]).mean() > 3
    assert np.array_equal(b["panorama"], c["panorama"])
