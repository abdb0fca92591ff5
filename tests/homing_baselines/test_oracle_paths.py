"""The oracle plans on the path the task's episodes are drawn joined by, and SPL measures
that same path; neither falls back to the straight line."""

import math

import numpy as np
import pytest

from homing_gym.paths import NoPathError, path_length, segment_free, shortest_path
from homing_gym.scenes.base import Landmark, Scene, Wall, square_walls
from homing_train.harness.evaluate import run_episode

ENV_ID = "homing_gym/LocalHoming-v0"
HOME = (1.3, 0.0, 0.0)
#: Starts whose straight way home is blocked (by the barrier, or a post on the way).
STARTS = ((-1.5, 0.0, 0.0), (-1.5, 1.5, 2.0), (0.4, -1.6, -1.0))


def cluttered() -> Scene:
    """A 4 m square walled in, a barrier at x = -0.8 with 0.6 m ways round its ends, and
    posts (cylinders of 0.15 m radius) 0.8 m apart on the right half."""
    posts = tuple(Landmark((x, y), shape="cylinder", radius=0.15, height=0.5)
                  for x in (0.0, 0.8) for y in (-1.2, -0.4, 0.4, 1.2))
    return Scene("cluttered", ((-2.0, -2.0), (2.0, 2.0)),
                 walls=(*square_walls(4.0), Wall((-0.8, -1.4), (-0.8, 1.4), thickness=0.1)),
                 landmarks=(*posts, Landmark((0.8, 0.0), shape="cylinder", radius=0.15)))


def test_the_starts_need_detours():
    assert not any(segment_free(cluttered(), s, HOME, 0.22) for s in STARTS)


@pytest.mark.parametrize("start", STARTS)
def test_oracle_reaches_home_round_the_clutter_on_the_path_spl_measures(start, make_env,
                                                                      controller_for):
    env = make_env(ENV_ID, scene=cluttered(), panorama_shape=(16, 64), success_on="stop",
                   max_episode_steps=400)
    oracle = controller_for("oracle", env)
    obs, info = env.reset(seed=0, options={"start": start, "home": HOME})
    oracle.reset()
    oracle.predict(obs)
    planned = oracle._path                                  # its plan from the start
    u = env.unwrapped
    assert planned == shortest_path(u.scene, info["start_pose"], HOME, u.task.path_radius)
    record = run_episode(env, oracle, seed=0, start=start, home=HOME)
    assert record.success and record.collisions == 0
    assert record.final_distance < 0.05
    assert record.shortest_path == pytest.approx(path_length(planned), abs=1e-9)
    assert record.shortest_path > math.dist(start[:2], HOME[:2]) + 0.1    # a real detour
    assert record.path_length < 1.2 * record.shortest_path


class Still:
    """A policy that never moves (its episode's metrics need no controller's help)."""

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return np.zeros(2, np.float32), state


def test_a_start_out_of_reach_is_an_error_not_a_straight_line(make_env, controller_for):
    rooms = Scene("two_rooms", ((-2.0, -1.0), (2.0, 1.0)),
                  walls=(Wall((0.0, -1.0), (0.0, 1.0), thickness=0.1),))
    env = make_env(ENV_ID, scene=rooms, panorama_shape=(16, 64), max_episode_steps=3)
    start, home = (-1.0, 0.0, 0.0), (1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match=r"episode of seed 0: SPL is undefined, no path joins"):
        run_episode(env, Still(), seed=0, start=start, home=home)
    oracle = controller_for("oracle", env)
    obs, _ = env.reset(seed=0, options={"start": start, "home": home})
    oracle.reset()
    with pytest.raises(NoPathError, match="no free path"):
        oracle.predict(obs)
