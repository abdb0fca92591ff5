"""The per-scene generalisation figure reads a protocol folder as homing-suite writes it."""

import json

import imageio.v2 as imageio
import numpy as np
import pytest

from homing_train.figures.generalisation import (TILE, by_camera_height_markdown,
                                                 failure_kinds_markdown, failures_figure,
                                                 load_results, per_scene_markdown)
from homing_train.harness.evaluate import EpisodeRecord, EvalResult
from homing_train.harness.matrix import setting_stem


def _episode(seed: int, success: bool) -> EpisodeRecord:
    return EpisodeRecord(seed=seed, start_pose=[0.5, 0.0, 0.0], home_pose=[-0.5, 0.0, 0.0],
                         start_distance=1.0, shortest_path=1.0, success=success,
                         terminated=True, truncated=False, steps=10, path_length=1.0,
                         final_distance=0.05 if success else 0.6, min_distance=0.05,
                         collisions=0, spl=float(success), soft_spl=0.5,
                         final_heading_error_deg=0.0, wall_time=0.1,
                         trajectory=[[0.5, 0.0], [0.2, 0.1], [-0.1, 0.2]])


def _write_cell(folder, method: str, outcomes: dict[str, list[bool]],
                kwargs: dict[str, dict] | None = None) -> None:
    """A method's cell as run_cell writes it: one result JSON per setting (env kwargs
    ``kwargs[label]``, else the arena's), cell.json."""
    cell = folder / method
    cell.mkdir(parents=True)
    for label, successes in outcomes.items():
        env_kwargs = (kwargs or {}).get(label, {"scene": "arena"})
        EvalResult(method, {}, "homing_gym/LocalHoming-v0", env_kwargs, 0,
                   [_episode(s, ok) for s, ok in enumerate(successes)]).save(
            str(cell / f"{setting_stem(label)}.json"))
    (cell / "cell.json").write_text(json.dumps({"method": method, "settings": {
        label: {"episodes": len(v)} for label, v in outcomes.items()}}))


def test_per_scene_table_counts_successes_with_wilson_intervals(tmp_path):
    _write_cell(tmp_path, "warping", {"arena (held out)": [True, False],
                                      "lab (held out)": [True, True]})
    _write_cell(tmp_path, "snapshot", {"arena (held out)": [False, False],
                                       "lab (held out)": [True, False]})
    results = load_results(tmp_path)
    assert [r.label for r in results["warping"]] == ["arena (held out)", "lab (held out)"]
    table = per_scene_markdown(results).splitlines()
    # 1 of 2: Wilson 95 % = 0.5 +- 1.96 sqrt(0.125 + 0.2401) / 2.9208 = [0.09, 0.91]
    # over both scenes: 3 of 4 -> (0.75 + 0.4802) / 1.9604 +- 1.96 * 0.32696 / 1.9604
    assert "| warping | 50 [9, 91] (2) | 100 [34, 100] (2) | 75 [30, 95] (4) |" in table
    assert "| snapshot | 0 [0, 66] (2) | 50 [9, 91] (2) | 25 [5, 70] (4) |" in table


def test_failure_kinds_count_each_failed_episode_once_over_all_scenes(tmp_path):
    _write_cell(tmp_path, "warping", {"arena": [True, False, False], "lab": [False, True]})
    results = load_results(tmp_path)
    # the hand-made failures: stopped 0.6 m away (the default radius 0.15 m + 0.1 m is
    # 0.25 m); make one stuck (out of time, 8 of 10 steps in contact), one near, one lost
    arena, lab = (r.result.episodes for r in results["warping"])
    arena[1].truncated, arena[1].collisions = True, 8
    arena[2].final_distance = 0.2
    lab[0].truncated = True
    table = failure_kinds_markdown(results).splitlines()
    assert table[0] == ("| method | episodes | success | stuck | out of time | stopped near "
                        "| stopped away |")
    assert table[2] == "| warping | 5 | 2 | 1 | 1 | 1 | 0 |"


def test_failures_figure_has_a_row_per_method_that_failed(tmp_path):
    _write_cell(tmp_path / "cells", "oracle", {"arena": [True, True]})
    _write_cell(tmp_path / "cells", "warping", {"arena": [True, False]})
    _write_cell(tmp_path / "cells", "snapshot", {"arena": [False, False]})
    results = load_results(tmp_path / "cells")
    failures_figure(results, tmp_path / "failures.png")
    image = imageio.imread(tmp_path / "failures.png")
    one_row = TILE + 22                                           # a tile under its label bar
    assert image.shape[0] == 2 * one_row                          # the oracle never failed
    assert np.ptp(image) > 0


def test_an_empty_folder_is_refused(tmp_path):
    with pytest.raises(ValueError, match="cell.json"):
        load_results(tmp_path)


def test_the_command_writes_the_tables_and_three_figures(tmp_path):
    from homing_train.figures.generalisation import main
    _write_cell(tmp_path / "cells", "warping", {"arena": [True, False]})
    assert main(["--cells", str(tmp_path / "cells"), "--out", str(tmp_path / "out")]) == 0
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == ["by_distance.png", "failure_kinds.md", "failures.png", "per_scene.md",
                       "per_scene.png"]
    assert imageio.imread(tmp_path / "out" / "by_distance.png").ndim == 3


def test_success_by_camera_height_bins_every_settings_episodes_by_their_worlds_height(tmp_path):
    low, high = {"scene": "arena", "camera_height": 0.05}, {"scene": "arena", "camera_height": 0.35}
    _write_cell(tmp_path, "warping", {"low": [True, True, True], "high": [False, True]},
                {"low": low, "high": high})
    _write_cell(tmp_path, "snapshot", {"low": [False, False, True], "high": [False, False]},
                {"low": low, "high": high})
    table = by_camera_height_markdown(load_results(tmp_path)).splitlines()
    assert table[0] == "| method | 0-0.1 m | 0.3-0.4 m |"
    # 3 of 3: Wilson 95 % [44, 100]; 1 of 2: [9, 91]; 1 of 3: [6, 79]; 0 of 2: [0, 66]
    assert "| warping | 100 [44, 100] (3) | 50 [9, 91] (2) |" in table
    assert "| snapshot | 33 [6, 79] (3) | 0 [0, 66] (2) |" in table


def test_no_camera_height_table_when_every_world_has_the_same_camera(tmp_path):
    _write_cell(tmp_path, "warping", {"arena": [True, False]})
    assert by_camera_height_markdown(load_results(tmp_path)) is None
