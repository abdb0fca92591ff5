"""homing-suite with no arguments: the headline's plan (protocols, methods, episode
counts) and the reading generated from its numbers; no episode runs here."""

from __future__ import annotations

import pytest

import homing_baselines
from homing_train.harness import suite
from homing_train.harness.headline import (HEADLINE_EPISODES, headline_plan, headline_table,
                                           learned_reading, protocol_reading, reading)
from homing_train.harness.matrix import Cell, cell_methods
from homing_train.harness.metrics import wilson_interval
from homing_train.harness.policies import DEFAULT_POLICY, shipped_policies


def cell(protocol: str, method: str, k: int, n: int) -> Cell:
    """A hand-made cell: ``k`` of ``n`` episodes stopped at the goal."""
    return Cell(protocol=protocol, version=1, method=method, command="",
                summary={"success_rate": k / n, "success_ci": list(wilson_interval(k, n)),
                         "episodes": n}, settings={})


def test_the_headline_plan_is_the_held_out_worlds_and_the_papers_protocols():
    plan = headline_plan()
    names = [p.name for p in plan.protocols]
    assert names == ["unseen", "local-common", "hong1991", "yukim", "bekris-lab",
                     "briggs-corridors", "shiraishi-house"]
    classical = {m for p in plan.protocols for m in cell_methods(p)
                 if m in homing_baselines.available()}
    assert classical == {"oracle", "random", "snapshot", "warping", "min-warping", "distance",
                         "alv", "did", "bearing", "bearing-basic", "bearing-complementary",
                         "selfsimilar", "multires"}
    learned = [m for m in plan.methods if m not in homing_baselines.available()]
    assert set(plan.methods) == classical | {DEFAULT_POLICY} and learned == [DEFAULT_POLICY]
    assert DEFAULT_POLICY in shipped_policies()
    assert plan.episodes == HEADLINE_EPISODES
    # every setting's tasks: 6 worlds in unseen and local-common, yukim and bekris-lab
    # draw at least one episode per distance bin (4) and per goal (6)
    assert plan.cell_episodes == {
        "unseen": 6 * HEADLINE_EPISODES["unseen"],
        "local-common": 6 * HEADLINE_EPISODES["local-common"],
        "hong1991": HEADLINE_EPISODES["hong1991"], "yukim": 4, "bekris-lab": 6,
        "briggs-corridors": HEADLINE_EPISODES["briggs-corridors"],
        "shiraishi-house": HEADLINE_EPISODES["shiraishi-house"]}
    assert "unseen: 12 episodes per cell" in plan.describe()


def test_episodes_and_methods_replace_the_headlines():
    plan = headline_plan(episodes=3, methods=["warping", "ppo"])
    assert set(plan.episodes.values()) == {3} and plan.methods == ("warping", DEFAULT_POLICY)
    with pytest.raises(ValueError, match="episodes must be >= 1, got 0"):
        headline_plan(episodes=0)


def _fake_matrix(calls: list):
    def run_matrix(protocols, out, episodes, workers, methods, **kwargs):
        calls.append((protocols, episodes, workers, methods, kwargs))
        return [cell(p.name, m, 1, 2) for p in protocols for m in cell_methods(p)
                if m in methods]
    return run_matrix


def test_no_arguments_run_the_headline_and_end_with_its_table_and_reading(
        monkeypatch, tmp_path, capsys):
    calls: list = []
    monkeypatch.setattr(suite, "run_matrix", _fake_matrix(calls))
    monkeypatch.setattr(suite, "run_suite", lambda *a, **k: pytest.fail("the one-env suite"))
    assert suite.main(["--out", str(tmp_path / "out")]) == 0
    (protocols, episodes, workers, methods, kwargs), = calls
    plan = headline_plan()
    assert [p.name for p in protocols] == [p.name for p in plan.protocols]
    assert episodes == plan.episodes and methods == plan.methods and kwargs["by_cell"]
    assert workers == suite.DEFAULT_WORKERS
    out = capsys.readouterr().out
    assert "| method | unseen (n=2) |" in out and "Reading" in out


@pytest.mark.parametrize("argv", [["--arena"], ["--scene", "hallway"],
                                  ["--env", "homing_gym/LocalHoming-v0"],
                                  ["--success-on", "reach"]])
def test_arena_or_a_one_env_option_runs_the_one_env_comparison(monkeypatch, tmp_path, argv):
    ran = []
    table = tmp_path / "table.md"
    table.write_text("| method |")

    def run_suite(*args, **kwargs):
        ran.append(args)
        return {"table": str(table)}
    monkeypatch.setattr(suite, "run_matrix", lambda *a, **k: pytest.fail("the headline"))
    monkeypatch.setattr(suite, "run_suite", run_suite)
    assert suite.main([*argv, "--out", str(tmp_path / "out")]) == 0
    assert ran


def test_arena_and_protocols_are_one_or_the_other(tmp_path, capsys):
    with pytest.raises(SystemExit) as err:
        suite.main(["--protocols", "yukim", "--arena", "--out", str(tmp_path / "out")])
    assert err.value.code == 2 and "drop --arena" in capsys.readouterr().err


def test_a_leader_whose_interval_clears_the_others_is_named_as_leading():
    cells = [cell("p", "oracle", 20, 20), cell("p", "warping", 19, 20),
             cell("p", "snapshot", 2, 20), cell("p", "random", 0, 20)]
    text = protocol_reading(cells)
    assert text.startswith("p: warping 95% [") and "clears every other method's" in text
    assert "next: snapshot 10% [" in text and "oracle" not in text


def test_overlapping_intervals_claim_no_ranking():
    cells = [cell("p", "warping", 3, 4), cell("p", "snapshot", 2, 4),
             cell("p", "distance", 0, 4)]
    text = protocol_reading(cells)
    assert text.startswith("p: warping 75% [") and "no ranking can be claimed" in text
    assert "overlaps snapshot 50% [15, 85] and distance 0% [0, 49]" in text  # [30, 95]
    assert "ahead of" not in text


def test_a_leader_tied_with_some_is_ahead_of_the_others():
    cells = [cell("p", "ppo", 12, 12), cell("p", "distance", 8, 12),
             cell("p", "warping", 0, 12)]
    text = protocol_reading(cells)
    assert "overlaps distance 67%" in text
    assert text.endswith("ahead of warping 0% [0, 24] (intervals apart).")


def test_the_learned_policy_is_set_against_the_best_classical_one_on_held_out_worlds():
    ahead = [cell("unseen", DEFAULT_POLICY, 19, 20), cell("unseen", "warping", 4, 20),
             cell("unseen", "snapshot", 1, 20), cell("unseen", "oracle", 20, 20)]
    assert "ahead, the intervals apart" in learned_reading(ahead)
    assert "best classical method, warping 20%" in learned_reading(ahead)
    close = [cell("unseen", DEFAULT_POLICY, 3, 4), cell("unseen", "warping", 2, 4)]
    assert "no difference can be claimed" in learned_reading(close)
    assert learned_reading([cell("yukim", DEFAULT_POLICY, 4, 4)]) == ""


def test_the_reading_covers_every_protocol_and_states_the_counts():
    cells = [cell("unseen", "warping", 3, 12), cell("unseen", DEFAULT_POLICY, 10, 12),
             cell("yukim", "random", 0, 4), cell("yukim", "distance", 0, 4)]
    text = reading(cells)
    assert f"- unseen: {DEFAULT_POLICY} 83%" in text and "- yukim: no method" in text
    assert "On held-out worlds (unseen)" in text and "4-12 episodes" in text
    table = headline_table(cells)
    assert "| method | unseen (n=12) | yukim (n=4) |" in table
    assert "| random |  | 0 [0, 49] |" in table


@pytest.mark.slow                      # about 20 s: two pools of spawned workers
def test_cells_run_whole_by_worker_processes_give_the_in_process_cells_and_resume(tmp_path):
    import json

    from homing_train.harness.matrix import run_matrix
    from homing_train.harness.protocols import protocol

    hong = [protocol("hong1991")]
    serial = run_matrix(hong, tmp_path / "serial", {"hong1991": 2}, 1, ["oracle", "snapshot"],
                        progress=False)
    by_cell = run_matrix(hong, tmp_path / "cells", {"hong1991": 2}, 2, ["oracle", "snapshot"],
                         by_cell=True)
    assert [(c.method, c.summary["success_rate"], c.summary["spl"]) for c in by_cell] == \
        [(c.method, c.summary["success_rate"], c.summary["spl"]) for c in serial]
    episodes = tmp_path / "cells" / "hong1991" / "oracle" / "hallway_1_ft.json"
    before = [e["wall_time"] for e in json.loads(episodes.read_text())["episodes"]]
    run_matrix(hong, tmp_path / "cells", {"hong1991": 2}, 2, ["oracle", "snapshot"],
               resume=True, by_cell=True)
    assert [e["wall_time"] for e in json.loads(episodes.read_text())["episodes"]] == before
    assert len(json.loads((tmp_path / "cells" / "matrix.json").read_text())) == 2
