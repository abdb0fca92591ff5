"""LongRangeHoming-v0: the env drives the outbound route while the agent watches, then
the agent homes; reproducible from the seed; clear errors on bad arguments."""

import math

import gymnasium as gym
import numpy as np
import pytest

from homing_gym.scenes import Scene, square_walls

ENV_ID = "homing_gym/LongRangeHoming-v0"


def _outbound(env, seed, actions):
    obs, info = env.reset(seed=seed)
    assert obs["phase"] == 0 and info["distance_to_goal"] < 1e-6   # starts at home
    poses, k = [], 0
    while obs["phase"] == 0:
        obs, reward, terminated, truncated, info = env.step(actions(k))
        k += 1
        assert reward == 0.0 and not terminated and not truncated
        poses.append(info["pose"])
    return np.array(poses), info


@pytest.mark.slow
def test_outbound_route_is_driven_by_the_env_and_ignores_the_agent(make_env):
    env = make_env(ENV_ID, route_length=2.0)
    still, info = _outbound(env, 5, lambda k: np.zeros(2, np.float32))
    wild, info2 = _outbound(env, 5, lambda k: np.array([1.0, (-1) ** k], np.float32))
    assert np.allclose(still, wild)
    route = info["route"]
    length = np.sum(np.hypot(*np.diff(route, axis=0).T))
    assert length == pytest.approx(2.0)
    assert math.dist(still[-1][:2], route[-1]) < 0.05                 # at the route's end
    assert np.allclose(route[0], info["goal_pose"][:2])              # from home
    assert info["phase"] == 1 and info["outbound_steps"] == len(still)
    assert info["collisions"] == 0
    # homing phase: the agent's actions count, rewards are paid
    obs, reward, *_ , info = env.step(np.array([1.0, 0.0], np.float32))
    assert obs["phase"] == 1 and reward != 0.0
    assert math.dist(info["pose"][:2], still[-1][:2]) > 0.01


def test_routes_are_reproducible_from_the_seed(make_env):
    env = make_env(ENV_ID)
    routes = [env.reset(seed=s)[1]["route"] for s in (3, 3, 4)]
    assert np.array_equal(routes[0], routes[1]) and not np.array_equal(routes[0], routes[2])
    length = np.sum(np.hypot(*np.diff(routes[0], axis=0).T))
    assert length == pytest.approx(8.0)
    obs, info = env.reset(seed=3)
    assert set(obs) == {"panorama", "goal", "phase"}
    diff = np.abs(obs["goal"].astype(int) - obs["panorama"])        # goal = home snapshot
    assert diff.mean() < 1.0


@pytest.mark.parametrize("kwargs, match", [
    ({"route_length": 0.1}, "route_length"),
    ({"outbound_speed": -0.1}, "outbound_speed"),
    ({"outbound_speed": 0.5}, "max_speed"),
    ({"outbound_yaw_rate": float("nan")}, "outbound_yaw_rate"),
    ({"scene": Scene("closet", ((-0.5, -0.5), (0.5, 0.5)), walls=square_walls(1.0))},
     "too small"),
    ({"obs_keys": ("panorama", "phase", "pose")}, "obs_keys"),
])
def test_bad_arguments_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        gym.make(ENV_ID, **kwargs)


def test_a_scene_without_room_for_the_route_raises_at_reset(make_env):
    scene = Scene("box", ((-0.7, -0.7), (0.7, 0.7)), walls=square_walls(1.4))
    env = make_env(ENV_ID, scene=scene)
    with pytest.raises(ValueError, match="cannot hold a route"):
        env.reset(seed=0)


def test_planned_routes_keep_their_margin_all_along_every_leg():
    # sampled every centimetre, not only where the planner looked (every 5 cm)
    from homing_gym.scenes import scene_factory
    from homing_gym.scenes.base import clearances
    from homing_gym.tasks.base import random_route, sample_free_pose

    scene = scene_factory("lab").build(np.random.default_rng(0))
    margin = 0.3
    for seed in range(30):
        rng = np.random.default_rng(seed)
        route = random_route(scene, sample_free_pose(scene, rng, margin), rng, 8.0, margin)
        assert sum(math.dist(a, b) for a, b in zip(route[:-1], route[1:])) == \
            pytest.approx(8.0)
        for a, b in zip(route[:-1], route[1:]):
            t = np.linspace(0.0, 1.0, max(2, math.ceil(math.dist(a, b) / 0.01) + 1))[:, None]
            free = clearances(scene, a + t * (b - a))
            assert free.min() >= margin - 0.01, (seed, a, b, free.min())
