"""``motion="kinematic"``: the unicycle without dynamics drives PyBullet's arcs on free
floor, stops at obstacles without entering them, and is refused where it cannot run."""

import math

import gymnasium as gym
import numpy as np
import pytest

from homing_gym.scenes.base import clearance
from homing_gym.sim.kinematic import KinematicRobot
from homing_gym.sim.robot import RobotConfig
from homing_gym.scenes import scene_factory


def _drive(motion, command, steps=15):
    env = gym.make("homing_gym/LocalHoming-v0", motion=motion, odometry_noise=0.0,
                   obs_keys=["panorama", "goal", "odometry"])
    env.reset(seed=0, options={"start": (0.0, 0.0, 0.0)})
    for _ in range(steps):
        obs, _, _, _, info = env.step(np.array(command, np.float32))
    env.close()
    return info["pose"], obs["odometry"], info["collisions"]


@pytest.mark.parametrize("command", [(1.0, 0.0), (0.5, 0.5), (0.3, -1.0), (0.0, 1.0)])
def test_on_free_floor_it_drives_pybullets_arcs(command):
    """1.5 s of one command from rest in the arena's free middle: the kinematic robot ends
    within 1.5 cm and 0.1 rad of PyBullet's (whose wheels slip a little in turns), and
    its odometry within 1.5 cm and 0.1 rad of its own true pose change (no noise)."""
    (p_pose, _, p_hits), (k_pose, k_odo, k_hits) = (_drive("pybullet", command),
                                                    _drive("kinematic", command))
    assert p_hits == k_hits == 0
    assert math.hypot(*(p_pose[:2] - k_pose[:2])) < 0.015
    assert abs(p_pose[2] - k_pose[2]) < 0.1
    assert math.hypot(*(k_odo[:2] - k_pose[:2])) < 0.015 and abs(k_odo[2] - k_pose[2]) < 0.1


def test_the_exact_arc_of_a_constant_command():
    """At full speed after the ramp, a straight command moves max_speed per second."""
    config = RobotConfig()
    robot = KinematicRobot(scene_factory("arena").build(None), config)
    robot.set_pose(-0.5, 0.0, 0.0)
    robot.drive(config.max_speed, 0.0)
    robot.move(120, 1 / 120)                                 # 1 s: ramp (0.15 s) then cruise
    ramp = config.max_speed / config.wheel_acceleration      # seconds to full speed
    expected = config.max_speed * (1 - ramp) + config.max_speed * ramp / 2
    assert robot.pose()[0] + 0.5 == pytest.approx(expected, abs=2e-3)
    assert robot.pose()[1] == pytest.approx(0.0, abs=1e-12)


def test_walls_stop_it_at_its_radius_and_count_collisions():
    """Driving at a wall for 6 s: a collision on the steps that bump, the body never
    nearer the wall than its radius, and it can back away."""
    env = gym.make("homing_gym/LocalHoming-v0", motion="kinematic")
    env.reset(seed=0, options={"start": (0.0, 0.0, 0.0)})
    scene, radius = env.unwrapped.scene, env.unwrapped.robot_config.body_radius
    hits = []
    for _ in range(60):
        _, _, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
        hits.append(info["collision"])
        assert clearance(scene, info["pose"][:2]) >= radius - 1e-9
    assert any(hits) and hits[-1]
    stuck = info["pose"].copy()
    _, _, _, _, info = env.step(np.array([-1.0, 0.0], np.float32))
    for _ in range(5):
        _, _, _, _, info = env.step(np.array([-1.0, 0.0], np.float32))
    assert info["pose"][0] < stuck[0] - 0.05 and not info["collision"]
    env.close()


def test_it_is_refused_where_it_cannot_run_and_named_in_results():
    from homing_gym.env import simulation_settings

    with pytest.raises(ValueError, match="motion='kinematic' needs drive='differential'"):
        gym.make("homing_gym/LocalHoming-v0", motion="kinematic", renderer="tiny")
    with pytest.raises(ValueError, match="motion='kinematic' needs drive='differential'"):
        gym.make("homing_gym/LocalHoming-v0", motion="kinematic", drive="synchro")
    with pytest.raises(ValueError, match="unknown motion 'teleport'"):
        gym.make("homing_gym/LocalHoming-v0", motion="teleport")
    assert simulation_settings({"motion": "kinematic"})["motion"] == "kinematic"
    assert "motion" not in simulation_settings({})
