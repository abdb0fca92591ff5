"""RouteFollowing-v0: the route's geometry, goal switching, per-target errors, both modes,
routes given as points."""

import math

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
    env = make_env(ROUTE, panorama_shape=(16, 64), success_on="reach")
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


def test_default_route_is_the_straight_route(make_env):
    env = make_env(ROUTE, start_jitter=(0.0, 0.0))
    env.reset(seed=1)
    x0, y0, yaw = env.unwrapped.scene.metadata["route_origin"]
    episode = env.unwrapped.episode
    straight = [(x0 + k * FOOT * math.cos(yaw), y0 + k * FOOT * math.sin(yaw), yaw)
                for k in range(17)]
    assert np.allclose(episode.goals, straight)
    assert np.allclose(episode.start, (x0 - FOOT, y0, yaw))


def test_given_route_sets_start_targets_and_travel_yaw(make_env):
    route = [(1.0, 0.0), (1.5, 0.5), (2.0, 0.5, 1.0), (2.5, 0.0), (2.0, -0.5)]
    env = make_env(ROUTE, route=route, start_jitter=(0.0, 0.0))
    _, info = env.reset(seed=0)
    episode = env.unwrapped.episode
    assert np.allclose(episode.start, (1.0, 0.0, math.pi / 4))     # towards the first target
    assert np.allclose(episode.goals, [(1.5, 0.5, math.pi / 4),        # travel direction
                                       (2.0, 0.5, 1.0),                 # given
                                       (2.5, 0.0, -math.pi / 4),
                                       (2.0, -0.5, -3 * math.pi / 4)])
    assert np.allclose(info["pose"], episode.start, atol=1e-3)
    assert info["target_index"] == 0 and np.allclose(info["goal_pose"], episode.goals[0])


def test_given_route_needs_no_route_origin(make_env):
    plain = Scene("plain", ((-1, -1), (1, 1)), walls=square_walls(2.0))
    env = make_env(ROUTE, scene=plain, route=[(-0.5, 0.0), (0.0, 0.0), (0.5, 0.5)])
    env.reset(seed=0)
    assert len(env.unwrapped.episode.goals) == 2


@pytest.mark.parametrize("kwargs, message", [
    ({"route": [(1.0, 0.0)]}, "at least two points"),
    ({"route": []}, "at least two points"),
    ({"route": "1,0 2,0"}, "route file '1,0 2,0': unknown format"),   # a string: a path
    ({"route": [(1.0, 0.0), (2.0, float("nan"))]}, r"route point 1 must be .* finite"),
    ({"route": [(1.0, 0.0), (2.0, 0.0, float("inf"))]}, r"route point 1 must be .* finite"),
    ({"route": [(1.0, 0.0), (2.0,)]}, r"route point 1 must be \(x, y\) or \(x, y, yaw\)"),
    ({"route": [(1.0, 0.0), (2.0, 0.0, 0.0, 0.0)]}, r"route point 1 must be"),
    ({"route": [(1.0, 0.0), 2.0]}, r"route point 1 must be"),
    ({"route": [(1.0, 0.0), ("2", 0.0)]}, r"route point 1 must be"),
    ({"route": [(1.0, 0.0), (2.0, 0.0), (2.0, 0.0)]}, r"points 1 .* and 2 .* are 0.000 m apart"),
    ({"route": [(1.0, 0.0), (1.03, 0.0)]}, r"at least 0.05 m apart"),
    ({"route": [(1.0, 0.0), (9.0, 0.0)]}, r"route point 1 \(9.000, 0.000\) lies outside the "
                                          r"bounds .* x in \[0.0, 8.0\]"),
    ({"route": [(1.0, 0.0), (2.0, 0.85)]}, r"route point 1 \(2.000, 0.850\) is 0.0\d\d m from "
                                           r"the nearest wall .* needs 0.160 m"),
    ({"route": [(2.7, 0.6), (3.5, 0.0)]}, r"route point 0 .* is 0.000 m from"),    # the bin
    ({"route": [(1.0, 0.0), (2.0, 0.0)], "n_targets": 5}, r"n_targets \(5\) and spacing"),
    ({"route": [(1.0, 0.0), (2.0, 0.0)], "spacing": 0.5}, r"spacing \(0.5\)"),
])
def test_bad_routes_are_refused(kwargs, message):
    import gymnasium as gym

    with pytest.raises(ValueError, match=message):
        gym.make(ROUTE, **kwargs)


def _turns(goals: np.ndarray) -> np.ndarray:
    legs = np.diff(goals[:, :2], axis=0)
    heading = np.arctan2(legs[:, 1], legs[:, 0])
    return np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)


@pytest.mark.parametrize("scene", ["random_nature", "random_rooms", "lab"])
def test_random_routes_are_clear_curved_and_drawn_from_the_seed(make_env, scene):
    from homing_gym.paths import joined_in_order
    from homing_gym.scenes.base import clearances
    from homing_gym.tasks.route_following import RANDOM_ROUTE_TURN

    env = make_env(ROUTE, scene=scene, route="random", n_targets=12, spacing=0.4,
                   panorama_shape=(16, 64))
    routes = []
    for seed in (0, 1, 0):
        _, info = env.reset(seed=seed)
        task, world = env.unwrapped.task, env.unwrapped.scene
        points = np.array([task._route(world)[0], *env.unwrapped.episode.goals])
        assert len(points) == 13
        assert np.allclose(np.hypot(*np.diff(points[:, :2], axis=0).T), 0.4)
        assert _turns(points).max() <= RANDOM_ROUTE_TURN + 1e-9
        assert clearances(world, points[:, :2]).min() >= task.clearance_margin - 1e-6
        assert joined_in_order(world, points, task.clearance_margin).all()
        assert math.dist(info["pose"][:2], points[0, :2]) <= 0.05 * math.sqrt(2) + 1e-3
        routes.append(points)
    assert np.array_equal(routes[0], routes[2]) and not np.allclose(routes[0], routes[1])


def test_random_routes_teach_the_views_of_each_episodes_route(make_env):
    # the last teaching view stands at the last target facing along the last leg: the
    # last target's snapshot; a new episode's route brings new views
    env = make_env(ROUTE, scene="random_nature", route="random", n_targets=5, spacing=0.3,
                   route_view_spacing=0.3, panorama_shape=(16, 64), action_type="discrete",
                   obs_keys=("panorama", "goal", "route_views"))
    views = []
    for seed in (2, 3):
        obs, _ = env.reset(seed=seed)
        assert obs["route_views"].shape == (6, 16, 64, 3)
        for _ in range(4):                             # stop at once: the next target
            obs, *_ = env.step(3)
        assert np.array_equal(obs["route_views"][-1], obs["goal"])
        views.append(obs["route_views"])
    assert not np.array_equal(*views)


@pytest.mark.parametrize("kwargs, message", [
    ({"scene": "arena", "n_targets": 40, "spacing": 2.0}, r"scene 'arena' .* holds no random "
                                                          r"route of 40 legs of 2.0 m"),
    ({"scene": "arena", "spacing": 0.08}, r"success_radius 0.1 m: a random route's start"),
])
def test_random_routes_that_cannot_be_drawn_are_refused(kwargs, message):
    import gymnasium as gym

    env = None
    with pytest.raises(ValueError, match=message):
        env = gym.make(ROUTE, route="random", **kwargs)
        env.reset(seed=0)
    if env is not None:
        env.close()
