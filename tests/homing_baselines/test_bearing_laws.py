"""Bearing-only homing laws of Bekris, Argyros & Kavraki (homing_baselines.bearing_laws) and
their pure 2-D simulator (homing_baselines.bearing_sim)."""

import math

import numpy as np
import pytest

from homing_baselines.bearing_laws import (Criterion, UnifiedConfig, UnifiedLaw, UnifiedState,
                                    angular_separations, basic_law, complementary_law,
                                    cyclic_order, eq1_gain, inside_triangle, landmark_pairs,
                                    motion_vectors, nearest_landmark_pair, snapshots_similar)
from homing_baselines.bearing_sim import (SimConfig, bearings, circumcircle, reachability_map, region,
                                   simulate, simulate_batch)

PI = math.pi
# The landmark triangle of docs/bearing.md; circle C^ centre (0.079, -0.088), radius 1.194.
LANDMARKS = np.array([[-1.0, -0.6], [1.2, -0.5], [0.2, 1.1]])


# --------------------------------------------------------------------------------------
# Eq. 1-2 and the complementary law on hand-computed cases
# --------------------------------------------------------------------------------------

def test_eq1_gain_folds_large_differences():
    # Eq. 1: d for |d| <= pi; 2 pi - d for d > pi; -2 pi - d for d < -pi.
    # 2 pi - 3.5 = 2.78319, -2 pi + 3.5 = -2.78319; continuous at +-pi (value +-pi).
    d = np.array([0.0, 1.0, -1.0, PI, -PI, 3.5, -3.5, 6.0])
    want = np.array([0.0, 1.0, -1.0, PI, -PI, 2.78319, -2.78319, 0.28319])
    np.testing.assert_allclose(eq1_gain(d), want, atol=1e-5)
    assert eq1_gain(PI + 1e-9) == pytest.approx(PI) and eq1_gain(-PI - 1e-9) == pytest.approx(-PI)


def test_angular_separations_are_ccw_in_0_2pi():
    # pairs (0,1), (0,2), (1,2); theta_ij = (beta_j - beta_i) mod 2 pi.
    # beta = [0, 4, 2]: (0,1) = 4, (0,2) = 2, (1,2) = 2 - 4 + 2 pi = 4.28319.
    assert landmark_pairs(3) == ((0, 1), (0, 2), (1, 2))
    np.testing.assert_allclose(angular_separations([0.0, 4.0, 2.0]), [4.0, 2.0, 4.28319],
                               atol=1e-5)


def test_basic_and_complementary_symmetric_case():
    # Current: L0 east (0), L1 north (pi/2), L2 west (pi). Goal: L1 seen 0.2 rad further
    # counter-clockwise (pi/2 + 0.2), the others unchanged.
    #   theta  = (pi/2, pi, pi/2), theta' = (pi/2 + 0.2, pi, pi/2 - 0.2)
    #   Delta  = (+0.2, 0, -0.2)
    #   delta_ij directions beta_i + theta_ij / 2 = (pi/4, pi/2, 3 pi/4)
    #   M_01 = 0.2 (cos pi/4, sin pi/4) = (0.14142, 0.14142)
    #   M_02 = 0
    #   M_12 = -0.2 (cos 3pi/4, sin 3pi/4) = (0.14142, -0.14142)
    #   basic M = (0.28284, 0): straight east.
    # NLP: pi-differences |pi - theta'| = (pi/2 - 0.2, 0, pi/2 + 0.2) -> pair (0, 2).
    #   complementary M = M_02 - M_01 - M_12 = (-0.28284, 0): straight west.
    cur = [0.0, PI / 2, PI]
    goal = [0.0, PI / 2 + 0.2, PI]
    res = basic_law(cur, goal)
    np.testing.assert_allclose(res.delta_theta, [0.2, 0.0, -0.2], atol=1e-12)
    np.testing.assert_allclose(res.pair_vectors, [[0.141421, 0.141421], [0, 0],
                                                  [0.141421, -0.141421]], atol=1e-6)
    np.testing.assert_allclose(res.vector, [0.282843, 0.0], atol=1e-6)
    assert res.direction == pytest.approx(0.0, abs=1e-9)
    assert res.nlp == 1 and res.pairs[res.nlp] == (0, 2)
    assert nearest_landmark_pair(goal) == 1
    comp = complementary_law(cur, goal)
    np.testing.assert_allclose(comp.vector, [-0.282843, 0.0], atol=1e-6)
    assert abs(comp.direction) == pytest.approx(PI)
    np.testing.assert_allclose(comp.unit, [-1.0, 0.0], atol=1e-9)


def test_basic_law_reflex_bisector_case():
    # Current beta = (0, 4.0, 2.0), goal beta' = (0, 4.2, 2.0) (radians).
    #   theta  = (4.0, 2.0, 4.28319)  [(0,1) > pi: reflex angle]
    #   theta' = (4.2, 2.0, 4.08319),  Delta = (+0.2, 0, -0.2)
    #   delta_01 along 0 + 4.0/2 = 2.0 rad: the reflex bisector, opposite to the convex
    #   bisector 4.0 + (2 pi - 4.0)/2 = 5.14159 = 2.0 + pi.
    #   delta_12 along 4.0 + 4.28319/2 = 6.14159.
    #   M_01 = 0.2 (cos 2, sin 2)            = 0.2 (-0.41615, 0.90930) = (-0.08323, 0.18186)
    #   M_12 = -0.2 (cos 6.14159, sin 6.14159) = -0.2 (0.98999, -0.14112) = (-0.19800, 0.02822)
    #   M = (-0.28123, 0.21008)
    res = basic_law([0.0, 4.0, 2.0], [0.0, 4.2, 2.0])
    np.testing.assert_allclose(res.theta, [4.0, 2.0, 4.28319], atol=1e-5)
    np.testing.assert_allclose(res.pair_vectors[0], [-0.08323, 0.18186], atol=1e-5)
    np.testing.assert_allclose(res.pair_vectors[2], [-0.19800, 0.02822], atol=1e-5)
    np.testing.assert_allclose(res.vector, [-0.28123, 0.21008], atol=1e-5)


def test_eq1_fold_in_a_pair_vector():
    # Current beta = (0, 0.5, 2.5), goal (0, 4.0, 2.5): Delta_01 = 4.0 - 0.5 = 3.5 > pi, so
    # Eq. 1 gives (2 pi - 3.5) = 2.78319 along delta_01 = 0.25 rad:
    #   M_01 = 2.78319 (cos 0.25, sin 0.25) = (2.69661, 0.68857).
    res = basic_law([0.0, 0.5, 2.5], [0.0, 4.0, 2.5])
    np.testing.assert_allclose(res.pair_vectors[0], [2.69661, 0.68857], atol=1e-4)


def test_laws_are_compass_free_and_order_free():
    rng = np.random.default_rng(3)
    cur = rng.uniform(-PI, PI, 3)
    goal = rng.uniform(-PI, PI, 3)
    m = basic_law(cur, goal).vector
    # A constant rotation of the goal snapshot changes nothing (no compass needed).
    np.testing.assert_allclose(basic_law(cur, goal + 1.234).vector, m, atol=1e-12)
    # Rotating the current frame by phi rotates M by phi (M is in the current frame).
    phi = 0.7
    c, s = math.cos(phi), math.sin(phi)
    np.testing.assert_allclose(basic_law(cur + phi, goal).vector,
                               [c * m[0] - s * m[1], s * m[0] + c * m[1]], atol=1e-12)
    # Relabelling the landmarks in both snapshots changes nothing (M_ij = M_ji).
    perm = [2, 0, 1]
    np.testing.assert_allclose(basic_law(cur[perm], goal[perm]).vector, m, atol=1e-12)
    np.testing.assert_allclose(complementary_law(cur[perm], goal[perm]).vector,
                               complementary_law(cur, goal).vector, atol=1e-12)


def test_basic_vector_points_towards_goal_near_goal():
    # Ideal bearings from the simulator: near a goal inside T^, M points at the goal.
    goal = np.array([0.1, -0.1])
    for offset in ([0.05, 0.0], [0.0, -0.05], [-0.04, 0.03]):
        pos = goal + offset
        res = basic_law(bearings(LANDMARKS, pos), bearings(LANDMARKS, goal))
        to_goal = -np.asarray(offset) / np.hypot(*offset)
        assert res.unit @ to_goal > 0.7


def test_batched_vectors_match_single():
    rng = np.random.default_rng(0)
    cur = rng.uniform(-PI, PI, (5, 4))
    goal = rng.uniform(-PI, PI, (5, 4))
    batch = motion_vectors(cur, goal)
    comp = motion_vectors(cur, goal, complementary=True)
    for k in range(5):
        np.testing.assert_allclose(batch[k], basic_law(cur[k], goal[k]).vector, atol=1e-12)
        np.testing.assert_allclose(comp[k], complementary_law(cur[k], goal[k]).vector,
                                   atol=1e-12)


# --------------------------------------------------------------------------------------
# Stop test and the geometric criteria on bearings
# --------------------------------------------------------------------------------------

def test_stop_test():
    goal = np.array([0.3, 2.0, 4.0])
    assert snapshots_similar(goal + 0.001, goal)              # same view, rotated robot
    assert snapshots_similar(goal + 1.0, goal)                # any rotation: compass-free
    assert not snapshots_similar(goal + 1.0, goal, aligned=True)
    assert snapshots_similar(goal + 0.004, goal, aligned=True)
    assert not snapshots_similar(goal + [0.0, 0.01, 0.0], goal)   # one separation off 0.01
    assert snapshots_similar(goal + [0.0, 0.01, 0.0], goal, tol=0.011)
    # Across the 0 / 2 pi seam: 0 and 2 pi - 0.001 are the same direction.
    assert snapshots_similar([0.0, 1.0, 2 * PI - 1e-3], [2 * PI - 1e-3, 1.0, 0.0], tol=0.01)


def test_triangle_and_order_criteria():
    # Criterion 1: consecutive gaps all < pi <=> inside the triangle.
    assert inside_triangle([0.0, 2 * PI / 3, 4 * PI / 3])
    assert not inside_triangle([0.0, 0.3, 0.6])
    assert not inside_triangle([0.0, PI / 2, PI])          # gap exactly pi: on an edge
    # Cyclic order: (0, 1, 2) counter-clockwise vs (0, 2, 1).
    assert list(cyclic_order([0.0, 2.0, 4.0])) == [0, 1, 2]
    assert list(cyclic_order([0.0, 0.6, 0.3])) == [0, 2, 1]
    # Against the geometry: the simulator's regions and ideal bearings agree.
    pts = np.array([[0.1, -0.1], [0.6, 3.0], [-2.5, 1.5], [0.2, -0.95]])
    assert list(region(LANDMARKS, pts)) == ["T", "H", "rest", "C-T"]
    inside = [bool(inside_triangle(bearings(LANDMARKS, p))) for p in pts]
    assert inside == [True, False, False, False]
    ref = cyclic_order(bearings(LANDMARKS, pts[0]))
    differs = [bool(np.any(cyclic_order(bearings(LANDMARKS, p)) != ref)) for p in pts]
    assert differs == [False, True, False, False]           # only H^ sees another order


def test_unified_first_two_criteria():
    # Criterion 1: goal snapshot inside T^ -> BASIC at the first step.
    law = UnifiedLaw()
    law.step([0.0, 2.0, 4.0], [0.1, 2.1, 4.2])
    assert law.state is UnifiedState.BASIC and law.criterion is Criterion.GOAL_IN_TRIANGLE
    # Criterion 2: A inside T^ (order 0, 1, 2), T sees (0, 2, 1) within less than pi:
    # T in H^ -> BASIC.
    law = UnifiedLaw()
    res = law.step([0.0, 2.0, 4.0], [0.0, 0.6, 0.3])
    assert law.state is UnifiedState.BASIC and law.criterion is Criterion.GOAL_IN_H
    np.testing.assert_allclose(res.vector, basic_law([0.0, 2.0, 4.0], [0.0, 0.6, 0.3]).vector)
    # Neither: A outside T^, T outside T^ -> UNCERTAIN, moving like the basic law.
    law = UnifiedLaw()
    res = law.step([0.0, 0.5, 1.0], [0.0, 0.6, 1.3])
    assert law.state is UnifiedState.UNCERTAIN and law.criterion is Criterion.NONE
    np.testing.assert_allclose(res.vector, basic_law([0.0, 0.5, 1.0], [0.0, 0.6, 1.3]).vector)
    law.reset()
    assert law.state is UnifiedState.UNCERTAIN


# --------------------------------------------------------------------------------------
# The 2-D simulator: reachability of the three laws (§2, Fig. 4, Fig. 10)
# --------------------------------------------------------------------------------------

GOALS = {  # region -> goals (m); regions checked below
    "T": [(0.1, -0.1)],
    "C-T": [(0.2, -0.95)],
    "H": [(0.6, 3.0), (3.0, -2.0), (-2.8, -1.6)],
    "rest": [(-2.5, 1.5), (2.5, 2.0), (0.3, -2.2)],
}
STARTS = [(-3.0, 3.0), (0.1, 0.0), (2.5, -0.5), (0.0, -2.0)]   # rest, T^, H^, rest


@pytest.fixture(scope="module")
def runs():
    goals = [g for gs in GOALS.values() for g in gs]
    names = [k for k, gs in GOALS.items() for _ in gs]
    assert list(region(LANDMARKS, np.array(goals))) == names
    assert list(region(LANDMARKS, np.array(STARTS))) == ["rest", "T", "H", "rest"]
    starts = np.repeat(np.array(STARTS), len(goals), axis=0)
    goal_arr = np.tile(np.array(goals), (len(STARTS), 1))
    cfg = SimConfig(max_steps=1500)
    out = {law: simulate_batch(LANDMARKS, starts, goal_arr, law, cfg)
           for law in ("basic", "complementary", "unified")}
    return np.array(names * len(STARTS)), out


def test_unified_law_reaches_every_region(runs):
    names, out = runs
    res = out["unified"]
    assert res.success.all(), list(zip(names[~res.success], res.final_error[~res.success]))
    assert res.final_error.max() < 0.05
    # It ends in the law the paper prescribes: complementary exactly for the rest of the
    # plane; elsewhere BASIC, or still UNCERTAIN (which moves like BASIC) if no criterion
    # fired before the goal was reached.
    rest = names == "rest"
    assert (res.states[rest] == UnifiedState.COMPLEMENTARY).all()
    assert (res.states[~rest] != UnifiedState.COMPLEMENTARY).all()
    assert (res.states[names == "H"] == UnifiedState.BASIC).all()


def test_basic_law_fails_only_in_the_rest_of_the_plane(runs):
    # §2: basic reaches C^ and H^ from any start; Fig. 10: it fails at E (rest).
    names, out = runs
    res = out["basic"]
    assert res.success[names != "rest"].all()
    assert not res.success[names == "rest"].any()
    assert res.final_error[names == "rest"].min() > 1.0


def test_complementary_law_reaches_exactly_the_rest(runs):
    # Fig. 4b / Fig. 10: complementary fails at A (in T^) and C (in H^), reaches E.
    names, out = runs
    res = out["complementary"]
    assert res.success[names == "rest"].all()
    assert not res.success[names != "rest"].any()


def test_simulate_one_run_records_trajectory_and_states():
    res = simulate(LANDMARKS, (0.1, 0.0), (2.5, 2.0), "unified")
    assert res.success and res.stopped and res.final_error < 0.05
    assert res.trajectory.shape == (res.steps + 1, 2)
    np.testing.assert_allclose(res.trajectory[0], [0.1, 0.0])
    steps = np.hypot(*np.diff(res.trajectory, axis=0).T)
    np.testing.assert_allclose(steps, 0.01, atol=1e-12)       # fixed step
    assert res.states[0] == UnifiedState.UNCERTAIN
    assert res.states[-1] == UnifiedState.COMPLEMENTARY


def test_reachability_map_modes():
    xs = np.linspace(-3, 3, 4)
    cfg = SimConfig(max_steps=1200)
    by_goal = reachability_map(LANDMARKS, "basic", xs, xs, start=(0.1, 0.0), config=cfg)
    assert by_goal.reached.shape == (4, 4) and by_goal.vary == "goal"
    gx, gy = np.meshgrid(xs, xs)
    reg = region(LANDMARKS, np.stack([gx, gy], axis=-1))
    # Corners (+-3, +-3): (3, -3) and (-3, -3) are in H^ (reached); (-3, 3), (3, 3) rest.
    assert by_goal.reached[0, 0] and by_goal.reached[0, -1]
    assert not by_goal.reached[-1, 0] and not by_goal.reached[-1, -1]
    assert reg[0, 0] == "H" and reg[-1, 0] == "rest"
    by_start = reachability_map(LANDMARKS, "complementary", xs, xs, goal=(2.5, 2.0),
                                config=cfg)
    assert by_start.vary == "start" and by_start.goal is not None
    assert by_start.fraction > 0.8        # the complementary law reaches E from most starts
    with pytest.raises(ValueError, match="exactly one"):
        reachability_map(LANDMARKS, "basic", xs, xs)


def test_circumcircle():
    centre, radius = circumcircle([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    np.testing.assert_allclose(centre, [0.0, 0.0], atol=1e-12)
    assert radius == pytest.approx(1.0)


def _criterion_4_decision(config: UnifiedConfig, first: float, slope: float):
    """The unified law's state and step when ``A`` sits on the NLP arc (goal outside the
    triangle; the NLP pair (0, 2) keeps its goal separation) while both non-NLP
    differences drift by ``slope`` a step under alternating noise of +-0.002 rad, as the
    bearings of a robot stepping back and forth across its path do."""
    goal = np.array([0.0, 1.5, 2.6])
    law = UnifiedLaw(config)
    for k in range(40):
        x = first + slope * k + 0.002 * (-1) ** k
        law.step(goal + np.array([x, 0.0, x]), goal)
        if law.state != UnifiedState.UNCERTAIN:
            assert law.criterion == Criterion.NLP_CIRCLE_TREND
            return law.state, k
    return law.state, None


def test_criterion_4_from_arrival_reads_the_drift_under_noise_where_a_short_window_fails():
    window = UnifiedConfig(dwell=10, trend_steps=3)
    arrival = UnifiedConfig(dwell=10, trend_steps=3, trend_from="arrival", trend_margin=0.005)
    # growing differences: the complementary law; the 3-step window reads the noise
    assert _criterion_4_decision(window, 0.06, 0.001)[0] == UnifiedState.BASIC
    assert _criterion_4_decision(arrival, 0.06, 0.001)[0] == UnifiedState.COMPLEMENTARY
    # shrinking differences: the basic law either way
    assert _criterion_4_decision(arrival, 0.12, -0.001)[0] == UnifiedState.BASIC
    # no drift beyond the margin: no decision
    assert _criterion_4_decision(arrival, 0.06, 0.0) == (UnifiedState.UNCERTAIN, None)
    with pytest.raises(ValueError, match="trend_from"):
        UnifiedConfig(trend_from="start")
    with pytest.raises(ValueError, match="trend_margin"):
        UnifiedConfig(trend_margin=-0.1)


# --------------------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------------------

@pytest.mark.parametrize("fn", [basic_law, complementary_law, UnifiedLaw().step,
                                snapshots_similar])
def test_bad_bearings_raise(fn):
    with pytest.raises(ValueError, match="at least 3 landmarks, got 2"):
        fn([0.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match=r"goal bearings\[1\] is nan"):
        fn([0.0, 1.0, 2.0], [0.0, float("nan"), 2.0])
    with pytest.raises(ValueError, match=r"current bearings\[2\] is inf"):
        fn([0.0, 1.0, float("inf")], [0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match=r"shape \(3,\) but goal bearings have shape \(4,\)"):
        fn([0.0, 1.0, 2.0], [0.0, 1.0, 2.0, 3.0])


def test_bad_simulator_input_raises():
    with pytest.raises(ValueError, match="at least 3"):
        simulate(LANDMARKS[:2], (0, 0), (1, 1))
    with pytest.raises(ValueError, match="unknown law 'nope'"):
        simulate(LANDMARKS, (0, 0), (1, 1), "nope")
    with pytest.raises(ValueError, match="SimConfig.step"):
        SimConfig(step=0.0)
    with pytest.raises(ValueError, match="UnifiedConfig.dwell"):
        UnifiedConfig(dwell=0)
    with pytest.raises(ValueError, match="non-finite"):
        simulate(LANDMARKS, (0, float("nan")), (1, 1))
