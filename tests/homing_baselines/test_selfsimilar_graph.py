"""The landmark visibility graph: observations, shortest paths, expected shortest paths."""

import math

import pytest

from homing_baselines.selfsimilar_graph import VisibilityGraph


def _graph(p_direct: float, looks: int = 10) -> VisibilityGraph:
    """0 -> 2 directly (2 m, seen with probability p_direct), or 0 -> 1 -> 2 (3 m, always)."""
    g = VisibilityGraph()
    for k in range(looks):
        seen = {1: (1.5, 0.0)}
        if k < round(p_direct * looks):
            seen[2] = (2.0, 0.5)
        g.observe(0, seen)
    for _ in range(looks):
        g.observe(1, {2: (1.5, 1.0)})
    return g


def test_observations_count_looks_and_sightings():
    g = _graph(0.3)
    e = g.edge(0, 2)
    assert (e.looked, e.seen) == (10, 3) and e.probability == pytest.approx(0.3)
    assert g.edge(0, 1).probability == 1.0 and g.edge(2, 0) is None
    g.traversed(0, 1, 1.7)
    assert g.edge(0, 1).length == 1.7


def test_deterministic_path_replans_when_a_landmark_is_not_visible():
    g = _graph(1.0)
    assert g.shortest_path(0, 2) == [0, 2]
    g.mark_invisible(0, 2)
    assert g.shortest_path(0, 2) == [0, 1, 2]
    g.mark_invisible(1, 2)
    assert g.shortest_path(0, 2) is None


def test_expected_length_of_one_unreliable_edge_matches_the_closed_form():
    g = VisibilityGraph()
    g.observe(0, {1: (2.0, 0.0)})
    for _ in range(3):
        g.observe(0, {})          # seen once in four looks: p = 1/4
    values = g.expected_lengths(1, stay_cost=0.5)
    # E = p l + (1 - p)(s + E)  =>  E = l + s (1 - p) / p
    assert values[0] == pytest.approx(2.0 + 0.5 * 0.75 / 0.25, abs=1e-4)
    assert values[1] == 0.0


def test_expected_shortest_path_prefers_the_reliable_detour():
    g = _graph(0.2)
    values = g.expected_lengths(2, stay_cost=2.0)
    # with 2 seen now the direct edge is best; without it the sure detour beats waiting
    assert g.best_next(0, {1, 2}, values, 2.0) == 2
    assert g.best_next(0, {1}, values, 2.0) == 1
    # a cheap look makes waiting for the short edge worth it
    cheap = g.expected_lengths(2, stay_cost=0.01)
    assert g.best_next(0, {1}, cheap, 0.01) == 0
    assert values[0] <= 3.0 + 1e-6
    with pytest.raises(ValueError, match="stay_cost"):
        g.expected_lengths(2, stay_cost=0.0)


def test_unreachable_goal_has_infinite_expected_length():
    g = _graph(1.0)
    g.observe(5, {})
    assert math.isinf(g.expected_lengths(2, 1.0)[5])
