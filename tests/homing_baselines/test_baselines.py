"""Controllers: registry, motion helper, oracle and random."""

import math

import numpy as np
import pytest

import homing_baselines
from homing_baselines.motion import MotionHelper, MotionSpec, Move, integrate
from homing_train.harness.evaluate import run_episode
from homing_train.harness.policies import parse_params

ENV_ID = "homing_gym/LocalHoming-v0"


@pytest.mark.parametrize("style", ["turn_then_drive", "pursuit", "reversing"])
def test_motion_helper_translates_on_a_synchro_drive(style):
    helper = MotionHelper(MotionSpec(drive="synchro"), style)
    actions = helper.plan(Move(0.7, 0.1))            # 0.1 m at 0.03 m per step: 4 steps
    assert len(actions) == 4
    for a in actions:                                # the body-frame velocity, 5/6 speed
        assert np.allclose(a, [0.1 / 0.12 * math.cos(0.7), 0.1 / 0.12 * math.sin(0.7)],
                           atol=1e-6)
    assert helper.plan(Move(1.0, 0.0)) == []         # cannot turn on the spot
    with pytest.raises(ValueError, match="continuous"):
        MotionHelper(MotionSpec(action_type="discrete", drive="synchro"))


def test_registry_lists_and_makes_controllers():
    assert {"oracle", "random"} <= set(homing_baselines.available())
    c = homing_baselines.make("oracle", step_length=0.2)
    assert c.step_length == 0.2 and c.needs_env
    assert not homing_baselines.make("random").needs_env
    with pytest.raises(ValueError, match="available"):
        homing_baselines.make("nope")
    with pytest.raises(ValueError, match="no parameter"):
        homing_baselines.make("random", speed=3)
    with pytest.raises(ValueError, match="step_length"):
        homing_baselines.make("random", step_length=-1.0)


def test_parse_params_types_and_errors():
    assert parse_params(["step_length=0.25", "align_heading=false"], "oracle") == {
        "step_length": 0.25, "align_heading": False}
    assert parse_params(["seed=7"], "random") == {"seed": 7}
    with pytest.raises(ValueError, match="key=value"):
        parse_params(["step_length"], "oracle")
    with pytest.raises(ValueError, match="no parameter"):
        parse_params(["speed=1"], "oracle")
    with pytest.raises(ValueError, match="float"):
        parse_params(["step_length=far"], "oracle")


@pytest.mark.parametrize("action_type", ["continuous", "discrete"])
@pytest.mark.parametrize("style", ["turn_then_drive", "pursuit", "reversing"])
def test_motion_helper_reaches_the_move_target_kinematically(action_type, style):
    spec = MotionSpec(action_type=action_type)
    helper = MotionHelper(spec, style)
    # discrete moves are quantised to one step: 0.03 m and 0.15 rad
    tol = 0.01 if action_type == "continuous" else 0.06
    for direction in (0.0, 0.7, -1.9, 3.0):
        for distance in (0.0, 0.1, 0.45):
            actions = helper.plan(Move(direction, distance))
            pose = integrate(actions, spec)
            if distance > 0:
                assert math.hypot(pose[0] - distance * math.cos(direction),
                                  pose[1] - distance * math.sin(direction)) < tol
            else:
                assert abs(pose[2] - direction) < (0.01 if action_type == "continuous" else 0.08)
            for a in actions:  # no planned action may read as the stop signal
                if action_type == "continuous":
                    assert max(abs(a[0]), abs(a[1])) >= spec.stop_threshold
                else:
                    assert a != 3


def test_reversing_backs_up_instead_of_turning_round():
    spec = MotionSpec()                              # 0.15 rad and 0.03 m per step
    reversing, turning = MotionHelper(spec, "reversing"), MotionHelper(spec, "turn_then_drive")
    assert reversing.travel is None
    behind = Move(3.0, 0.06)                         # 0.14 rad off straight back
    actions = reversing.plan(behind)
    assert len(actions) == 3 and actions[0][1] < 0 and actions[0][0] == 0
    assert all(a[0] < 0 and a[1] == 0 for a in actions[1:])      # backwards, no turning
    assert reversing.travel == math.pi                # the robot now travels tail first
    assert len(turning.plan(behind)) == 22            # 20 turn steps, then 2 forward
    assert turning.travel == 0.0
    ahead = Move(1.2, 0.06)                           # within 90 degrees: as turn-then-drive
    assert [a.tolist() for a in reversing.plan(ahead)] == \
        [a.tolist() for a in turning.plan(ahead)]
    assert reversing.travel == 0.0
    reversing.plan(Move(3.0, 0.0))                    # a turn alone faces the direction
    assert reversing.travel == 0.0                    # and moves nothing: travel unchanged
    reversing.reset()                                 # a new episode: nothing travelled yet
    assert reversing.travel is None


def test_bad_moves_and_styles_raise():
    with pytest.raises(ValueError):
        Move(0.0, -1.0)
    with pytest.raises(ValueError):
        Move(math.nan, 1.0)
    with pytest.raises(ValueError, match="motion"):
        homing_baselines.make("random", motion="teleport")


@pytest.mark.parametrize("name, params, words", [
    ("warping", {"smooth_deg": "2"}, ["smooth_deg", "finite number", "'2'"]),
    ("warping", {"smooth_deg": math.inf}, ["smooth_deg", "inf"]),
    ("snapshot", {"k_high": math.nan}, ["k_high", "nan"]),
    ("oracle", {"align_heading": "yes"}, ["align_heading", "True or False", "'yes'"]),
    ("oracle", {"step_length": True}, ["step_length", "True"]),
    ("random", {"seed": -1}, ["seed", "integer >= 0", "-1"]),
    ("multires", {"vfov_deg": math.nan}, ["vfov_deg", "nan"]),
    ("multires", {"heading_tolerance_deg": -5.0}, ["heading_tolerance_deg", "-5.0"]),
    ("bearing", {"colors": 5}, ["colors", "5"]),
])
def test_parameters_of_the_wrong_kind_or_range_are_refused(name, params, words):
    with pytest.raises(ValueError) as err:
        homing_baselines.make(name, **params)
    for word in words:
        assert word in str(err.value)


def test_random_controller_is_reproducible_per_episode_seed():
    def directions(seed):
        c = homing_baselines.make("random")
        c.reset(seed)
        out = []
        for _ in range(40):
            c.predict({})
            out.append(c.last_direction)
        return out

    assert directions(5) == directions(5)
    assert directions(5) != directions(6)


def test_non_oracle_refuses_the_env():
    with pytest.raises(TypeError, match="observations only"):
        homing_baselines.make("random").attach_env(object())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_oracle_reaches_home_and_stops_there(seed, make_env, controller_for):
    env = make_env(ENV_ID, success_on="stop", max_episode_steps=300)
    record = run_episode(env, controller_for("oracle", env), seed)
    assert record.success and record.terminated
    assert record.final_distance < 0.06
    assert record.final_heading_error_deg < 6.0
    assert record.path_length < 1.3 * record.shortest_path + 0.1


def test_oracle_discrete_actions_reach_home(make_env, controller_for):
    env = make_env(ENV_ID, action_type="discrete", max_episode_steps=300)
    record = run_episode(env, controller_for("oracle", env), 4)
    assert record.success and record.final_distance < 0.15


#: Routes as (scene, points): an S of 6 targets in the hallway; an L round the corner of
#: the house's living room into the bedroom (x = 3.5, then through the door at y = 1.5);
#: targets in the kitchen and then the bedroom of the house, each reached only round the
#: walls (the oracle plans a path for each target).
ROUTES = {
    "hallway-s": ("hallway", [(1.0 + 0.5 * k, 0.4 * math.sin(k * math.pi / 3))
                              for k in range(7)]),
    "house-l": ("house", [(2.0, 3.0), (2.75, 3.0), (3.5, 3.0), (3.5, 2.25), (3.5, 1.5),
                          (4.5, 1.5), (5.5, 1.5)]),
    "house-rooms": ("house", [(2.0, 3.0), (6.0, 4.5), (6.0, 1.5)]),
}


@pytest.mark.parametrize("route", sorted(ROUTES))
def test_oracle_stops_at_every_target_of_a_route(route, make_env, controller_for):
    scene, points = ROUTES[route]
    env = make_env("homing_gym/RouteFollowing-v0", scene=scene, route=points,
                   success_on="stop", panorama_shape=(16, 64), max_episode_steps=800)
    oracle = controller_for("oracle", env)
    obs, info = env.reset(seed=0)
    oracle.reset(0)
    goals = env.unwrapped.episode.goals
    stops, terminated, truncated, t = [], False, False, 0
    while not (terminated or truncated):
        action, _ = oracle.predict(obs, episode_start=t == 0)
        index = info["target_index"]
        obs, _, terminated, truncated, info = env.step(action)
        t += 1
        if terminated or info["target_index"] != index:      # the oracle stopped there
            assert info["target_index"] == min(index + 1, len(goals) - 1)
            stops.append((index, env.unwrapped.pose.copy()))
    assert terminated and info["is_success"]
    assert [k for k, _ in stops] == list(range(len(goals)))
    assert len(info["target_errors"]) == len(goals) and max(info["target_errors"]) < 0.05
    for k, pose in stops:
        assert abs(math.remainder(pose[2] - goals[k][2], 2 * math.pi)) < 0.1
