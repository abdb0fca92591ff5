"""The ``lab`` scene of Bekris et al. Fig. 9 and the registered bearing-only controllers
(``bearing``, ``bearing-basic``, ``bearing-complementary``) homing from pixels."""

import gymnasium as gym
import numpy as np
import pytest

import homing_baselines
from homing_baselines.bearing import goal_bearings
from homing_baselines.bearing_sim import region
from homing_baselines.blobs import Blob
from homing_baselines.motion import Move
from homing_gym.envs import LocalHomingEnv
from homing_gym.scenes import available_scenes, scene_factory
from homing_gym.scenes.base import clearance
from homing_gym.sim.simulator import Simulator
from homing_train.harness.evaluate import evaluate, run_episode
from homing_train.harness.rollout import prepare_policy

ENV_ID = "homing_gym/LocalHoming-v0"
#: The region each marked position must lie in (Fig. 9b).
EXPECTED = {"A": "T", "F": "C-T", "C": "H", "D": "H", "B": "rest", "E": "rest"}


def test_lab_marks_lie_in_their_regions_of_fig_9b():
    scene = scene_factory("lab").build(np.random.default_rng(0))
    assert "lab" in available_scenes()
    triangle = np.array(list(scene.metadata["landmarks"].values()))
    circle = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    for name, point in scene.metadata["marked"].items():
        ring = np.array(point) + 0.2 * np.stack([np.cos(circle), np.sin(circle)], 1)
        assert set(region(triangle, np.vstack([point, ring]))) == {EXPECTED[name]}, name
        assert clearance(scene, point) > 0.3
    posters = {lm.name: lm.position for lm in scene.landmarks if lm.name.startswith("poster")}
    assert posters == {f"poster_{k}": v for k, v in scene.metadata["landmarks"].items()}


@pytest.fixture(scope="module")
def lab():
    env = gym.make(ENV_ID, scene="lab", success_on="stop", max_episode_steps=600)
    yield env
    env.close()


def _run(env, name, start, goal, **params):
    controller = homing_baselines.make(name, **params)
    prepare_policy(controller, env)
    marked = env.unwrapped.scene.metadata["marked"]
    return run_episode(env, controller, 0, start=start, home=(*marked[goal], 0.5)), controller


def test_unified_law_reaches_goal_a_from_pixels_and_stops(lab):
    record, controller = _run(lab, "bearing", (-2.0, 2.0, -1.0), "A")
    assert record.terminated and record.success and record.final_distance < 0.04
    assert controller._unified.state.name == "BASIC"       # criterion 1: T in T^


@pytest.mark.slow
def test_unified_law_switches_to_complementary_for_goal_e(lab):
    record, controller = _run(lab, "bearing", (-2.0, 2.0, -1.0), "E")
    assert record.terminated and record.final_distance < 0.10
    assert controller._unified.state.name == "COMPLEMENTARY"


@pytest.mark.slow
def test_basic_law_fails_where_the_complementary_law_succeeds(lab):
    """Fig. 10: from a start in C^, goal E (rest of the plane) is unreachable for the
    basic law and reachable for the complementary law."""
    basic, _ = _run(lab, "bearing-basic", (0.6, 0.1, 1.0), "E")
    comp, _ = _run(lab, "bearing-complementary", (0.6, 0.1, 1.0), "E")
    assert basic.final_distance > 0.5
    assert comp.terminated and comp.final_distance < 0.2


def _blobs(**specs) -> dict[str, Blob]:
    """Blobs by colour from ``name=(bearing, width)`` (radians)."""
    return {name: Blob(name, 0.0, 0.0, bearing, 10, width) for name, (bearing, width)
            in specs.items()}


def test_a_landmark_hidden_behind_a_column_takes_the_column_bearing():
    controller = homing_baselines.make("bearing")
    controller.reset()
    seen = controller.bearings_with_occluded(
        _blobs(red=(1.0, 0.1), green=(1.2, 0.1), blue=(-2.0, 0.1)))
    assert seen == {"red": 1.0, "green": 1.2, "blue": -2.0}
    # red vanished next to green (0.2 rad apart): behind green's column
    assert controller.bearings_with_occluded(_blobs(green=(1.1, 0.3), blue=(-2.1, 0.1))) \
        == {"green": 1.1, "blue": -2.1, "red": 1.1}
    # blue vanished far from every column: not occluded by one, still missing
    assert "blue" not in controller.bearings_with_occluded(_blobs(red=(1.0, 0.1),
                                                                  green=(1.2, 0.1)))


def test_a_landmark_missing_in_the_goal_is_behind_the_nearest_column():
    colors = ("red", "green", "blue")
    assert goal_bearings(_blobs(red=(0.5, 0.1), blue=(2.0, 0.3)), colors) == \
        {"red": 0.5, "blue": 2.0, "green": 2.0}
    assert goal_bearings(_blobs(red=(0.5, 0.1)), colors) == {"red": 0.5}


def test_the_robot_steps_round_a_near_column_in_its_way():
    controller = homing_baselines.make("bearing")
    controller.reset()
    goal = _blobs(red=(0.0, 0.1))
    near = _blobs(red=(0.0, 0.6))                       # 0.6 rad wide: about 0.33 m away
    move = controller.around_columns(Move(0.2, 0.05), near, goal)
    assert move == Move(np.pi / 2, 0.05)                 # perpendicular, on the move's side
    assert controller.around_columns(Move(-0.1, 0.05), near, goal).direction == np.pi / 2
    assert controller.around_columns(Move(2.0, 0.05), near, goal) == Move(2.0, 0.05)  # away
    far = _blobs(red=(0.0, 0.2))
    assert controller.around_columns(Move(0.2, 0.05), far, goal) == Move(0.2, 0.05)
    # the goal is nearer the column than the robot: let the law approach it
    assert controller.around_columns(Move(0.2, 0.05), near, _blobs(red=(0.0, 0.7))) \
        == Move(0.2, 0.05)


@pytest.mark.parametrize("start, goal", [
    ((-1.795, -0.771, -0.195), "A"),   # behind L1: the straight way to A runs into it
    ((0.33, 1.573, 1.291), "B"),       # L1 hidden behind L3 at the start
])
def test_unified_law_goes_round_and_past_the_columns(lab, start, goal):
    """Fig. 11 runs that used to end pressed against a landmark column."""
    record, _ = _run(lab, "bearing", start, goal)
    assert record.collisions == 0
    assert record.terminated and record.final_distance < 0.15


def test_bearing_controllers_run_in_the_harness_from_the_observation_only():
    result = evaluate("bearing", ENV_ID, episodes=2, seed=3, progress=False,
                      env_kwargs={"scene": "lab", "max_episode_steps": 30})
    assert result.env_kwargs["obs_keys"] == ["panorama", "goal"]
    assert len(result.episodes) == 2
    controller = homing_baselines.make("bearing")
    forbidden = (gym.Env, Simulator, LocalHomingEnv)
    env = gym.make(ENV_ID, scene="lab", max_episode_steps=20)
    try:
        prepare_policy(controller, env)
        run_episode(env, controller, 1)
    finally:
        env.close()
    assert not any(isinstance(v, forbidden) for v in vars(controller).values())
    with pytest.raises(TypeError, match="observations only"):
        controller.attach_env(env)


@pytest.mark.parametrize("params, match", [
    ({"colors": ("red", "green")}, "colors"),
    ({"colors": ("red", "green", "purple")}, "colors"),
    ({"min_step": 0.2}, "min_step"),
    ({"stop_tol": 0.0}, "stop_tol"),
    ({"gain": float("nan")}, "gain"),
    ({"min_area": 0}, "min_area"),
    ({"occlusion_gap": 0.0}, "occlusion_gap"),
    ({"near_width": 4.0}, "near_width"),
])
def test_bad_controller_parameters_raise(params, match):
    for name in ("bearing", "bearing-basic", "bearing-complementary"):
        with pytest.raises(ValueError, match=match):
            homing_baselines.make(name, **params)
