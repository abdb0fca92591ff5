"""Route metrics (RouteFollowing-v0): targets reached in order, target errors, and what
"reached" means on a route, against hand-computed values."""

import json

import pytest

from homing_train.harness.compare import route_table
from homing_train.harness.evaluate import (EpisodeRecord, EvalResult, evaluate, format_summary,
                                           summarize)
from homing_train.harness.metrics import targets_reached_in_order

TARGETS = [(1.0, 0.0), (2.0, 0.0), (3.0, 0.0)]


@pytest.mark.parametrize("positions, reached", [
    ([(0, 0), (1.05, 0), (1.5, 0), (2.0, 0.05), (2.5, 0), (2.95, 0.02)], 3),
    ([(0, 0), (1.05, 0), (1.5, 0), (2.0, 0.1)], 1),        # 0.1 is not closer than 0.1
    ([(0, 0), (2.0, 0), (3.0, 0), (1.0, 0)], 1),           # targets 2 and 3 before target 1
    ([(0, 0), (3.0, 0), (2.0, 0)], 0),                     # never near target 1
    ([(1.0, 0), (2.0, 0), (1.0, 0), (3.0, 0)], 3),
])
def test_targets_reached_in_order_hand_computed(positions, reached):
    assert targets_reached_in_order(positions, TARGETS, radius=0.1) == reached


def test_one_position_reaches_one_target_even_where_two_overlap():
    close = [(0.0, 0.0), (0.05, 0.0)]                      # both within 0.1 of (0.02, 0)
    assert targets_reached_in_order([(0.02, 0.0)], close, 0.1) == 1
    assert targets_reached_in_order([(0.02, 0.0), (0.03, 0.0)], close, 0.1) == 2


def _route_episode(seed, targets, errors, reached, min_distance, success=False):
    return EpisodeRecord(seed=seed, start_pose=[0, 0, 0], home_pose=[3, 0, 0],
                         start_distance=3.0, shortest_path=3.0, success=success,
                         terminated=success, truncated=not success, steps=10, path_length=3.0,
                         final_distance=0.5, min_distance=min_distance, collisions=0, spl=0.0,
                         soft_spl=0.0, final_heading_error_deg=0.0, wall_time=0.1,
                         targets=targets, target_errors=errors, targets_finished=len(errors),
                         targets_reached=reached,
                         all_targets_within_radius=len(errors) == targets
                         and all(e < 0.1 for e in errors))


def test_on_a_route_reached_counts_every_target_not_the_last_alone():
    """Three routes: every target within the radius; two of three targets left, one
    reached; none of 17 left, though the robot passed the last target (came within 5 cm
    of it: the old rule, min_distance, called that reached)."""
    episodes = [_route_episode(0, 3, [0.05, 0.08, 0.02], 3, 0.02, success=True),
                _route_episode(1, 3, [0.05, 0.2], 1, 0.05),
                _route_episode(2, 17, [], 0, 0.05)]
    s = summarize(episodes, radius=0.1)
    assert s["reached_rate"] == pytest.approx(1 / 3)
    assert s["success_rate"] == pytest.approx(1 / 3)
    assert s["route_episodes"] == 3
    assert s["targets_reached_fraction"] == pytest.approx((1 + 1 / 3 + 0) / 3)
    assert s["all_targets_within_radius_rate"] == pytest.approx(1 / 3)
    assert s["targets_finished_mean"] == pytest.approx((3 + 2 + 0) / 3)
    assert s["target_error_mean"] == pytest.approx((0.05 + 0.08 + 0.02 + 0.05 + 0.2) / 5)
    assert s["target_error_cm_median"] == pytest.approx(5.0)
    lo, hi = s["all_targets_within_radius_ci"]
    assert lo < 1 / 3 < hi
    assert "targets reached in order 44.4%" in format_summary(
        EvalResult("m", {}, "homing_gym/RouteFollowing-v0", {}, 0, episodes))


def test_homing_summaries_have_no_route_keys():
    homing = _route_episode(0, None, [], None, 0.05)
    homing = EpisodeRecord(**{**homing.__dict__, "targets": None, "target_errors": None,
                              "targets_finished": None, "all_targets_within_radius": None})
    s = summarize([homing], radius=0.1)
    assert s["reached_rate"] == 1.0 and "route_episodes" not in s


def test_oracle_on_a_route_file_reaches_every_target_and_the_result_records_them(tmp_path):
    """Reach mode: each target is left as soon as the robot is within the radius, so the
    env's count (target_errors) and the count from the trajectory agree."""
    route = tmp_path / "route.csv"
    route.write_text("x,y\n0.5,-0.8\n0.5,-0.3\n0.0,-0.3\n")
    result = evaluate("oracle", "homing_gym/RouteFollowing-v0", episodes=2, seed=0,
                      env_kwargs={"route": str(route), "scene": "arena"}, progress=False)
    for e in result.episodes:
        assert e.targets == 2 and e.targets_finished == 2 and e.targets_reached == 2
        assert e.all_targets_within_radius and all(err < 0.1 for err in e.target_errors)
    assert result.summary["reached_rate"] == 1.0
    assert result.summary["targets_reached_fraction"] == 1.0
    result.save(str(tmp_path / "r.json"))
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["env_kwargs"]["route"] == str(route)
    assert doc["episodes"][0]["targets_reached"] == 2
    loaded = EvalResult.load(str(tmp_path / "r.json"))
    assert loaded.episodes[0].target_errors == result.episodes[0].target_errors
    table = route_table([loaded])
    assert table.splitlines()[2].startswith("| oracle | 2 | 100.0 [100.0, 100.0] |")


def test_a_route_cut_short_counts_the_targets_it_reached(tmp_path):
    """Stop mode with too few steps: the oracle stops at the first target (left within
    the radius) and runs out of time before the second."""
    result = evaluate("oracle", "homing_gym/RouteFollowing-v0", episodes=1, seed=0,
                      env_kwargs={"route": [(0.5, -0.8), (0.5, -0.3), (-0.8, -0.8)],
                                  "scene": "arena", "success_on": "stop",
                                  "max_episode_steps": 60}, progress=False)
    (e,) = result.episodes
    assert (e.targets, e.targets_finished, e.targets_reached) == (2, 1, 1)
    assert not e.all_targets_within_radius and not e.success
    assert result.summary["reached_rate"] == 0.0
    assert result.summary["targets_reached_fraction"] == 0.5
