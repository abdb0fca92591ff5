"""Protocols and the methods x protocols matrix: episodes as the papers draw them, one
success rule, cells that reproduce from their command."""

import csv
import json
import math

import gymnasium as gym
import numpy as np
import pytest

import homing_gym  # noqa: F401
from homing_gym.scenes.base import clearance
from homing_train.harness import eval_command
from homing_train.harness.evaluate import EpisodeRecord, summarize
from homing_train.harness.policies import DEFAULT_POLICY
from homing_train.harness.matrix import (Cell, cell_methods, equal_time_kwargs, run_cell,
                                         write_matrix)
from homing_train.harness.protocols import (NEST, PROTOCOLS, marked_goal_starts, protocol,
                                            ring_starts, scene_named)


def test_every_protocol_makes_its_envs_with_the_stop_rule():
    for p in PROTOCOLS.values():
        assert p.methods and p.settings and p.version >= 1
        for setting in p.settings:
            assert setting.kwargs()["success_on"] == "stop"
            env = gym.make(setting.env_id, **setting.kwargs())
            env.close()
    with pytest.raises(ValueError, match="unknown protocol 'nope'"):
        protocol("nope")


def test_yukim_starts_lie_in_the_fig6_bins_around_the_nest():
    bins = ((0.3, 0.6), (0.6, 0.9), (0.9, 1.2), (1.2, 1.4))
    tasks = ring_starts("arena", NEST, bins, 5, seed=3)
    assert len(tasks) == 20 and len({t[0] for t in tasks}) == 20
    arena = scene_named("arena")
    for i, (seed, start, home) in enumerate(tasks):
        lo, hi = bins[i // 5]
        assert lo <= math.dist(start[:2], NEST[:2]) < hi
        assert clearance(arena, start[:2]) >= 0.22 and home == NEST
    assert ring_starts("arena", NEST, bins, 5, seed=3) == tasks          # seeded


def test_bekris_starts_are_half_to_three_metres_from_each_marked_goal():
    lab = scene_named("lab")
    marked = list(lab.metadata["marked"].values())
    tasks = marked_goal_starts("lab", 2, seed=11, goal_yaw=0.5)
    assert len(tasks) == 2 * len(marked)
    for i, (_, start, home) in enumerate(tasks):
        goal = marked[i // 2]
        assert np.allclose(home, (goal[0], goal[1], 0.5))
        assert 0.5 <= math.dist(start[:2], goal[:2]) <= 3.0


def test_a_policy_with_a_longer_control_period_gets_the_same_time():
    recorded = {"control_period": 0.2, "max_episode_steps": 200, "panorama_shape": [32, 128]}
    merged = equal_time_kwargs({"scene": "arena", "max_episode_steps": 300,
                                "success_on": "stop"}, recorded, 500)
    assert merged["max_episode_steps"] == 150 and merged["panorama_shape"] == [32, 128]
    assert merged["scene"] == "arena" and merged["success_on"] == "stop"
    # no cap in the setting: the env id's 500 steps of 0.1 s, not the 200 it trained with
    assert equal_time_kwargs({"scene": "lab"}, recorded, 500)["max_episode_steps"] == 250
    assert "max_episode_steps" not in equal_time_kwargs({"scene": "lab"}, recorded, None)
    same_period = equal_time_kwargs({"scene": "lab"}, {"max_episode_steps": 200}, 500)
    assert same_period["max_episode_steps"] == 500
    # a setting's own period: its 100 steps of 0.2 s are 20 s for every row
    slow = equal_time_kwargs({"scene": "lab", "control_period": 0.2, "max_episode_steps": 100},
                             recorded, 500)
    assert slow["control_period"] == 0.2 and slow["max_episode_steps"] == 100
    fast = equal_time_kwargs({"scene": "lab", "control_period": 0.2, "max_episode_steps": 100},
                             {"control_period": 0.1}, 500)
    assert fast["control_period"] == 0.2 and fast["max_episode_steps"] == 100


def test_a_policys_record_cannot_change_the_task():
    recorded = {"panorama_shape": [16, 128], "action_type": "discrete",
                "success_radius": 0.3, "start_distance": [0.3, 0.5], "stop_threshold": 0.5,
                "max_speed": 0.6, "lighting_change": 0.0, "odometry_origin": "home"}
    merged = equal_time_kwargs({"scene": "arena", "success_on": "stop",
                                "lighting_change": 0.3}, recorded, 500)
    assert merged == {"panorama_shape": [16, 128], "action_type": "discrete",
                      "scene": "arena", "success_on": "stop", "lighting_change": 0.3,
                      "max_episode_steps": 500}


def test_a_policy_keeps_its_own_renderer_and_physics():
    recorded = {"renderer": "tiny", "physics_substeps": 24, "panorama_shape": [32, 128]}
    merged = equal_time_kwargs({"scene": "random_rooms", "renderer": "raycast",
                                "physics_substeps": 12, "success_on": "stop"}, recorded, 500)
    assert merged["renderer"] == "tiny" and merged["physics_substeps"] == 24
    assert merged["scene"] == "random_rooms"


def test_protocols_pin_their_renderer_and_physics():
    """The protocols of homing-gym 0.1 (version 1) were measured with TinyRenderer and
    1/240 s, their later versions and the protocols made since (the families', routes) ray cast
    at 1/120 s; both are explicit, so a change of the env defaults changes no cell."""
    since_0_2 = {"unseen-families", "validation-families", "train-families", "routes"}
    for p in PROTOCOLS.values():
        for setting in p.settings:
            kwargs = setting.kwargs()
            old = p.version == 1 and p.name not in since_0_2
            expected = ("tiny", 24) if old else ("raycast", 12)
            assert (kwargs["renderer"], kwargs["physics_substeps"]) == expected


def test_unseen_worlds_are_held_out_seeds_of_every_procedural_world():
    unseen = protocol("unseen")
    scenes = [s.env_kwargs["scene"] for s in unseen.settings]
    assert {"random_arena", "random_rooms", "random_nature"} <= set(scenes)
    common = {seed for s in protocol("local-common").settings
              for seed, _, _ in s.episode_tasks(5, 0)}
    for setting in unseen.settings:            # every world's episodes its own (v3)
        seeds = [seed for seed, _, _ in setting.episode_tasks(5, 0)]
        assert all(seed >= 10_000_000 for seed in seeds) and not common & set(seeds)


def test_local_common_starts_in_no_world_a_training_env_started_in():
    # a training env i of a run with seed s starts in the world of seed s + i; shipped
    # runs used seeds below a million (and resumed at step counts below that)
    seeds = [seed for s in protocol("local-common").settings
             for seed, _, _ in s.episode_tasks(17, 0)]
    assert min(seeds) >= 20_000_000


def test_policies_expand_to_the_shipped_policies_of_the_protocols_env():
    methods = cell_methods(protocol("local-common"))
    assert "policies" not in methods and "oracle" in methods
    assert "ppo_procedural_long" in methods
    assert "ppo_procedural_long" not in cell_methods(protocol("briggs-corridors"))


def test_reached_counts_episodes_that_came_within_the_radius_at_any_time():
    def record(seed, success, min_distance):
        return EpisodeRecord(seed=seed, start_pose=[0, 0, 0], home_pose=[1, 0, 0],
                             start_distance=1.0, shortest_path=1.0, success=success,
                             terminated=success, truncated=not success, steps=10,
                             path_length=1.0, final_distance=0.5, min_distance=min_distance,
                             collisions=0, spl=0.0, soft_spl=0.0, final_heading_error_deg=0.0,
                             wall_time=0.1)
    s = summarize([record(0, True, 0.1), record(1, False, 0.12), record(2, False, 0.3),
                   record(3, False, 0.2)], radius=0.15)
    assert s["success_rate"] == 0.25 and s["reached_rate"] == 0.5


def test_oracle_cell_on_yukim_stops_at_the_nest_and_its_command_reproduces_it(tmp_path):
    cell = run_cell(protocol("yukim"), "oracle", tmp_path / "a", episodes=4, progress=False)
    assert cell.summary["episodes"] == 4                   # one start per Fig. 6 bin
    assert cell.summary["success_rate"] == 1.0             # stopped within 0.15 m each time
    assert cell.command == "homing-eval --protocol yukim --policy oracle --episodes 4 --out OUT.json"
    out = tmp_path / "b.json"
    assert eval_command.main(["--protocol", "yukim", "--policy", "oracle", "--episodes", "4",
                              "--quiet", "--out", str(out)]) == 0
    again = json.loads(out.read_text())
    assert again["summary"]["episodes"] == 4
    assert [s["success_rate"] for s in again["settings"].values()] == [1.0]
    assert again["summary"]["final_distance_mean"] == pytest.approx(
        cell.summary["final_distance_mean"])


def test_a_run_folders_model_runs_a_protocol_with_its_training_env_kwargs(tmp_path):
    """A PPO zip given by path (here a band-extractor model) gets its run folder's input
    format (16 x 64 panoramas) under the protocol's own scene, stop rule and time, and
    nothing else of its training env: not its camera height or lighting."""
    from homing_train.learning.train import main as train_main

    run = tmp_path / "run"
    train_main(["--timesteps", "64", "--out", str(run), "--extractor", "band", "--n-envs", "1",
                "--vec", "dummy", "--no-progress", "--env-kwargs",
                json.dumps({"panorama_shape": [16, 64], "max_episode_steps": 16,
                            "camera_height": 0.1, "lighting_change": 0.5}),
                "--hp", "n_steps=64", "--hp", "batch_size=32", "--hp", "n_epochs=1",
                "--hp", "features_dim=32"])
    model = str(run / "model.zip")
    cell = run_cell(protocol("yukim"), model, tmp_path / "cell", episodes=4, progress=False)
    assert cell.summary["episodes"] == 4 and cell.method == model
    (setting_path,) = [p for p in (tmp_path / "cell").glob("*.json") if p.name != "cell.json"]
    setting = json.loads(setting_path.read_text())
    assert setting["env_kwargs"]["panorama_shape"] == [16, 64]
    assert setting["env_kwargs"]["scene"] == "arena"
    assert setting["env_kwargs"]["success_on"] == "stop"
    assert "camera_height" not in setting["env_kwargs"]
    assert "lighting_change" not in setting["env_kwargs"]
    assert cell.privileged == ""                # no warm start from the oracle
    with pytest.raises(ValueError, match="or a PPO model .zip"):
        run_cell(protocol("yukim"), str(tmp_path / "missing.zip"), tmp_path / "x")


def test_protocol_mode_refuses_settings_the_protocol_fixes(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        eval_command.main(["--protocol", "yukim", "--policy", "oracle", "--env-kwargs",
                           '{"scene": "lab"}', "--out", str(tmp_path / "x.json")])
    assert exit_.value.code == 2 and "--protocol fixes" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        eval_command.main(["--protocol", "yukim", "--policy", "selfsimilar_nope",
                           "--out", str(tmp_path / "x.json")])
    capsys.readouterr()
    # an --out without extension would be both the cell's file and its settings' folder:
    # refused before any episode runs, nothing written
    with pytest.raises(SystemExit) as exit_:
        eval_command.main(["--protocol", "yukim", "--policy", "oracle",
                           "--out", str(tmp_path / "cell")])
    assert exit_.value.code == 2 and "needs an extension" in capsys.readouterr().err
    assert not (tmp_path / "cell").exists()


def test_matrix_files_name_every_cell_with_its_command(tmp_path):
    summary = {"episodes": 10, "success_rate": 0.3, "success_ci": [0.1, 0.6],
               "reached_rate": 0.5, "reached_ci": [0.2, 0.8], "spl": 0.25,
               "final_distance_mean": 0.42}
    cells = [Cell("yukim", 1, m, f"homing-eval --protocol yukim --policy {m} --out OUT.json",
                  summary, {}, privileged) for m, privileged in
             (("warping", ""), ("distance", ""), ("cloned", "oracle demonstrations"))]
    written = write_matrix(cells, tmp_path)
    text = open(written["md"]).read()
    assert "| warping | 30 [10, 60] |" in text
    assert "| cloned (privileged: oracle demonstrations) | 30 [10, 60] |" in text
    assert "`homing-eval --protocol yukim --policy distance --out OUT.json`" in text
    assert open(written["csv"]).read().count("\n") == 4
    assert all(row["success_on"] == "stop" for row in csv.DictReader(open(written["csv"])))
    assert all(cell["success_on"] == "stop" for cell in json.load(open(written["json"])))
    assert open(written["png"], "rb").read(4) == b"\x89PNG"


def test_merged_cells_replace_the_same_cell_and_keep_the_order():
    from homing_train.harness.matrix import merged_cells

    def cell(protocol, method, rate):
        return Cell(protocol, 1, method, "", {"success_rate": rate}, {})

    old = [cell("yukim", "warping", 0.1), cell("yukim", "distance", 0.2),
           cell("hong1991", "warping", 0.3)]
    new = [cell("yukim", "distance", 0.9), cell("bekris-lab", "bearing", 0.5)]
    got = merged_cells(old, new)
    assert [(c.protocol, c.method, c.summary["success_rate"]) for c in got] == [
        ("yukim", "warping", 0.1), ("yukim", "distance", 0.9), ("hong1991", "warping", 0.3),
        ("bekris-lab", "bearing", 0.5)]


def test_a_resumed_matrix_keeps_the_cells_it_did_not_run_again(tmp_path, monkeypatch):
    from homing_train.harness import matrix

    def fake_cell(protocol, method, out, episodes, *args):
        summary = {"episodes": episodes, "success_rate": 0.5, "success_ci": [0.2, 0.8],
                   "reached_rate": 0.5, "reached_ci": [0.2, 0.8], "spl": 0.4,
                   "final_distance_mean": 0.3}
        return Cell(protocol.name, protocol.version, method, f"run {episodes}", summary, {})

    monkeypatch.setattr(matrix, "run_cell", fake_cell)
    yukim = protocol("yukim")
    first, second = cell_methods(yukim)[:2]
    matrix.run_matrix([yukim], tmp_path, 10, methods=[first, second], progress=False)
    matrix.run_matrix([yukim], tmp_path, 20, methods=[second], progress=False, resume=True)
    kept = {(c.method, c.summary["episodes"]) for c in matrix.load_cells(tmp_path / "matrix.json")}
    assert kept == {(first, 10), (second, 20)}
    # without --resume a run writes the matrix of what it ran
    matrix.run_matrix([yukim], tmp_path, 30, methods=[second], progress=False)
    assert [c.method for c in matrix.load_cells(tmp_path / "matrix.json")] == [second]


def test_hong_starts_are_one_foot_from_home_with_the_homes_heading():
    from homing_train.harness.protocols import FOOT, common_heading_starts

    hallway = scene_named("hallway")
    for _, start, home in common_heading_starts("hallway", FOOT, 8, seed=2):
        assert math.dist(start[:2], home[:2]) == pytest.approx(0.3048)
        assert start[2] == home[2]
        assert min(clearance(hallway, start[:2]), clearance(hallway, home[:2])) >= 0.25


@pytest.mark.slow
def test_snapshot_homes_from_one_foot_on_the_synchro_drive(tmp_path):
    cell = run_cell(protocol("hong1991"), "snapshot", tmp_path, episodes=6, workers=2,
                    progress=False)
    # closed loop on the paper's robot and step; 8 of 10 in the docs' run
    assert cell.summary["success_rate"] >= 0.5, cell.summary


def test_readme_matrix_is_the_committed_matrix_with_every_cells_command():
    from pathlib import Path

    from homing_train.harness.matrix import (README_BEGIN, README_END, load_cells,
                                             matrix_markdown, readme_block)

    root = Path(__file__).resolve().parents[3]
    text = (root / "README.md").read_text()
    block = README_BEGIN + text.split(README_BEGIN)[1].split(README_END)[0] + README_END
    cells = load_cells(root / "docs/matrix/matrix.json")
    assert block == readme_block(cells, "docs/matrix/matrix.json")
    full = (root / "docs/matrix/matrix.md").read_text()
    assert full == matrix_markdown(cells)
    for c in cells:
        assert c.command.startswith(f"homing-eval --protocol {c.protocol} --policy {c.method}")
        assert f"`{c.command}`" in full and c.version == protocol(c.protocol).version


def test_field_in_a_protocol_uses_its_env_and_fixed_home(tmp_path):
    from homing_train.harness import field

    out = tmp_path / "f.png"
    assert field.main(["--protocol", "yukim", "--policy", "warping", "--grid", "0.8",
                       "--no-return", "--quiet", "--out", str(out)]) == 0
    doc = json.loads(out.with_suffix(".json").read_text())
    assert np.allclose(doc["home"][:2], NEST[:2])            # Yu & Kim's nest, not a drawn home
    assert doc["env_kwargs"]["success_on"] == "stop" and doc["env_kwargs"]["scene"] == "arena"
    with pytest.raises(SystemExit):
        field.main(["--protocol", "yukim", "--policy", "warping", "--scene", "lab",
                    "--out", str(out)])


PAPER_PROTOCOLS = ("hong1991", "yukim", "bekris-lab", "briggs-corridors", "shiraishi-house")


def test_every_paper_protocol_states_its_papers_claim_and_where():
    from homing_train.harness.protocols import Claim

    for name in PAPER_PROTOCOLS:
        p = protocol(name)
        assert p.claims, name
        for claim in p.claims:
            assert claim.method in p.methods and claim.text and claim.differs
            assert "§" in claim.where or "Fig." in claim.where
    assert protocol("hong1991").claims[0].runs == (17, 17)       # §5: all 17 homings
    assert {c.method: c.runs for c in protocol("bekris-lab").claims} == {
        "bearing": (180, 180), "bearing-basic": (18, 27), "bearing-complementary": (9, 27)}
    assert not protocol("local-common").claims and not protocol("yukim-anywhere").claims
    with pytest.raises(ValueError, match="runs"):
        Claim("x", "t", "", "§1", "d", runs=(5, 3))


def _cell(name, method, settings):
    """A cell with per-setting ``(k, n)`` and the summary over them (Wilson CIs)."""
    from homing_train.harness.metrics import wilson_interval

    k, n = sum(s[0] for s in settings.values()), sum(s[1] for s in settings.values())
    summary = {"episodes": n, "success_rate": k / n, "success_ci": list(wilson_interval(k, n)),
               "reached_rate": k / n, "reached_ci": list(wilson_interval(k, n)), "spl": 0.5,
               "final_distance_mean": 0.1}
    return Cell(name, PROTOCOLS[name].version if name in PROTOCOLS else 1, method,
                f"homing-eval --protocol {name} --policy {method} --out OUT.json", summary,
                {label: {"episodes": n_, "success_rate": k_ / n_, "reached_rate": k_ / n_}
                 for label, (k_, n_) in settings.items()})


def test_claims_table_sets_the_papers_runs_beside_our_cell():
    from homing_train.harness.matrix import claims_markdown

    text = claims_markdown([_cell("bekris-lab", "bearing-basic", {"lab, A-F": (8, 12)})])
    row = next(line for line in text.splitlines() if "| bearing-basic |" in line)
    # Fig. 10: 18 of 27 runs reached (Wilson 95%: 47.8-81.4%); ours 8 of 12
    assert "| 18/27 = 67% [48, 81] | 67 [39, 86] (8/12) |" in row
    assert "Fig. 10" in row and "goals A, C and E only" in row
    unrun = next(line for line in text.splitlines() if "| bearing |" in line)
    assert "180/180" in unrun and "not run" in unrun
    assert "hong1991" not in text                  # only protocols that are in the matrix


def test_aggregate_over_two_protocols_from_their_counts():
    from homing_train.harness.matrix import aggregate_markdown, strata_counts
    from homing_train.harness.metrics import aggregate_success

    def cells(n):
        return [_cell("p1", "a", {"s": (3 * n // 10, n)}),
                _cell("p2", "a", {"s": (7 * n // 10, n)}),
                _cell("p1", "b", {"s": (n, n)})]             # b did not run p2: left out

    assert strata_counts(cells(10), ("p1", "p2")) == {"a": [(3, 10), (7, 10)]}
    text = aggregate_markdown(cells(10), ("p1", "p2"))
    assert "| a | 2 | 20 | 50 [" in text and "| b |" not in text
    small, big = (aggregate_success(strata_counts(cells(n), ("p1", "p2"))["a"])
                  for n in (10, 100))
    assert small.mean == big.mean == small.iqm == 0.5          # 2 strata: IQM trims none
    assert small.mean_ci[0] < big.mean_ci[0] < 0.5 < big.mean_ci[1] < small.mean_ci[1]


def test_a_setting_two_protocols_share_counts_once_in_the_aggregate(monkeypatch):
    """unseen v2 repeated local-common's hallway, lab and house episodes: such shared
    settings count once; v3 draws its own, so every world counts."""
    import dataclasses

    from homing_train.harness import matrix
    from homing_train.harness.matrix import strata_counts

    common, unseen = protocol("local-common"), protocol("unseen")
    cells = [_cell("local-common", "m", {s.label: (i % 6, 5) for i, s in
                                         enumerate(common.settings)}),
             _cell("unseen", "m", {s.label: (1, 5) for s in unseen.settings})]
    assert len(strata_counts(cells)["m"]) == 12               # 6 + 6 worlds, none shared
    shared = dataclasses.replace(unseen, settings=(*unseen.settings[:3], *common.settings[1:4]))
    monkeypatch.setitem(matrix.PROTOCOLS, "unseen", shared)
    cells[1] = _cell("unseen", "m", {s.label: (1, 5) for s in shared.settings})
    counts = strata_counts(cells)["m"]
    assert len(counts) == 9 and counts[:6] == [(i % 6, 5) for i in range(6)]
    assert counts[6:] == [(1, 5)] * 3                        # the held-out procedural worlds


def test_matrix_command_rewrites_the_markdown_and_readme_block(tmp_path):
    from homing_train.harness.matrix import README_BEGIN, README_END, main, matrix_markdown

    cells = [_cell("yukim", "distance", {"arena, nest": (2, 12)})]
    (tmp_path / "m").mkdir()
    (tmp_path / "m/matrix.json").write_text(json.dumps([c.__dict__ for c in cells]))
    (tmp_path / "README.md").write_text(f"top\n{README_BEGIN}\nold\n{README_END}\nend\n")
    assert main(["m/matrix.json", "--readme", str(tmp_path / "README.md")]) == 0
    assert (tmp_path / "m/matrix.md").read_text() == matrix_markdown(cells)
    assert "Yu & Kim, §III, Fig. 6" in (tmp_path / "m/matrix.md").read_text()
    assert "| distance |" in (tmp_path / "README.md").read_text()


def test_a_method_that_knows_ground_truth_is_named_so_in_its_row():
    from homing_train.harness.matrix import matrix_markdown
    cells = [_cell("yukim", method, {"arena nest": (5, 10)})
             for method in ("oracle", "warping", "multires")]
    first_table = matrix_markdown(cells).split("\n\n")[1].splitlines()[2:]   # the success table
    rows = {line.split(" |")[0][2:] for line in first_table}
    assert rows == {"oracle (privileged: true poses and the world's map)", "warping",
                    "multires (privileged: the taught maps' 3-D feature points and target "
                    "poses, from the scene (map_points, map_pose))"}


def test_the_families_protocols_hold_out_the_test_families_with_their_own_seeds():
    """unseen-families measures exactly the test families, validation-families exactly
    the validation ones; no seed is shared between two families or the two protocols."""
    from homing_gym.scenes.families import families_in
    test, validation = protocol("unseen-families"), protocol("validation-families")
    train = protocol("train-families")
    assert [s.env_kwargs["scene"] for s in test.settings] == list(families_in("test"))
    assert [s.env_kwargs["scene"] for s in validation.settings] == list(families_in("validation"))
    assert [s.env_kwargs["scene"] for s in train.settings] == list(families_in("train"))
    seeds = [seed for p in (test, validation, train) for s in p.settings
             for seed, _, _ in s.episode_tasks(p.episodes, p.seed)]
    assert len(seeds) == len(set(seeds)) == 3 * 100 + 2 * 50 + 6 * 50
    assert all(s.env_kwargs["start_distance"] == [0.3, 2.0] for s in test.settings)


def test_a_policy_row_says_why_it_is_empty_where_no_policy_can_act():
    from homing_train.harness.matrix import matrix_markdown
    assert not [m for m in cell_methods(protocol("hong1991")) if m.startswith("ppo")]
    cells = [_cell("yukim", m, {"arena nest": (5, 10)}) for m in ("warping", DEFAULT_POLICY)]
    cells.append(_cell("hong1991", "warping", {"hallway, 1 ft": (9, 10)}))
    table = matrix_markdown(cells).split("\n\n")
    rows = {line.split(" | ")[0][2:]: line for line in table[1].splitlines()[2:]}
    assert rows[DEFAULT_POLICY].endswith("| n/a |")          # hong1991: it cannot drive it
    assert rows["warping"].endswith("| 90 [60, 98] |")
    assert table[2].startswith("n/a: no learned policy can act here. hong1991: the synchro")


def test_the_routes_protocol_lets_localhoming_policies_follow_its_targets():
    routes = protocol("routes")
    assert {s.env_id for s in routes.settings} == {"homing_gym/RouteFollowing-v0"}
    assert DEFAULT_POLICY in cell_methods(routes)
    assert {"perfect-memory", "infomax", "min-warping"} <= set(cell_methods(routes))
    assert [s.env_kwargs.get("route") for s in routes.settings] == [None, "random", "random"]
    assert all(s.kwargs()["success_radius"] == 0.15 for s in routes.settings)
    seeds = [seed for s in routes.settings for seed, _, _ in s.episode_tasks(10, routes.seed)]
    assert len(set(seeds)) == 30 and min(seeds) == 60_000_000
