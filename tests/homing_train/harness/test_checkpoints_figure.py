"""Choosing a run's checkpoints and tabulating their scores (no episodes run)."""

import json

import pytest

from homing_train.figures.checkpoints import (PRETRAIN_STEP, CheckpointScore, markdown,
                                              run_checkpoints)


def test_checkpoints_every_so_many_steps_in_step_order_after_the_warm_start(tmp_path):
    (tmp_path / "checkpoints").mkdir()
    for steps in (100000, 25000, 50000, 75000):
        (tmp_path / "checkpoints" / f"ppo_{steps}_steps.zip").write_bytes(b"")
    (tmp_path / "checkpoints" / "notes.zip").write_bytes(b"")
    chosen = run_checkpoints(tmp_path, every=50000)
    assert [(s, p.name) for s, p in chosen] == [(50000, "ppo_50000_steps.zip"),
                                                (100000, "ppo_100000_steps.zip")]
    (tmp_path / "pretrain_model.zip").write_bytes(b"")
    assert [s for s, _ in run_checkpoints(tmp_path, every=25000)] == [
        PRETRAIN_STEP, 25000, 50000, 75000, 100000]
    assert [s for s, _ in run_checkpoints(tmp_path, every=30000)] == [PRETRAIN_STEP, 50000,
                                                                      100000]
    with pytest.raises(ValueError, match="no checkpoints at 200000 steps or later"):
        run_checkpoints(tmp_path / "checkpoints", every=200000)


def test_checkpoints_stay_spread_after_a_resume_shifted_them(tmp_path):
    (tmp_path / "checkpoints").mkdir()
    steps = [25000 * k for k in range(1, 21)] + [543744 + 25000 * k for k in range(4)]
    for s in steps:
        (tmp_path / "checkpoints" / f"ppo_{s}_steps.zip").write_bytes(b"")
    chosen = [s for s, _ in run_checkpoints(tmp_path, every=50000)]
    assert chosen == [50000 * k for k in range(1, 11)] + [568744, 618744]


def test_the_final_model_closes_the_series_unless_a_checkpoint_has_its_steps(tmp_path):
    (tmp_path / "checkpoints").mkdir()
    for steps in (50000, 100000):
        (tmp_path / "checkpoints" / f"ppo_{steps}_steps.zip").write_bytes(b"")
    (tmp_path / "model.zip").write_bytes(b"")
    (tmp_path / "summary.json").write_text(json.dumps({"timesteps": 120848}))
    assert [(s, p.name) for s, p in run_checkpoints(tmp_path, every=50000)] == [
        (50000, "ppo_50000_steps.zip"), (100000, "ppo_100000_steps.zip"),
        (120848, "model.zip")]
    (tmp_path / "summary.json").write_text(json.dumps({"timesteps": 100000}))
    assert [s for s, _ in run_checkpoints(tmp_path, every=50000)] == [50000, 100000]


def test_table_gives_success_with_interval_and_counts():
    scores = [CheckpointScore(PRETRAIN_STEP, 30, 12, (0.246, 0.577), "c0"),
              CheckpointScore(50000, 30, 3, (0.035, 0.256), "c1")]
    lines = markdown({"run_a": scores}, "unseen").splitlines()
    assert lines[0] == "| run | env steps | unseen: success % [95% CI] | episodes |"
    assert lines[2] == "| run_a | warm start | 40 [25, 58] | 12/30 |"
    assert lines[3] == "| run_a | 50,000 | 10 [4, 26] | 3/30 |"


def test_since_keeps_the_late_checkpoints_and_the_final_model_only(tmp_path):
    (tmp_path / "checkpoints").mkdir()
    for steps in (100000, 200000, 300000, 400000):
        (tmp_path / "checkpoints" / f"ppo_{steps}_steps.zip").write_bytes(b"")
    (tmp_path / "pretrain_model.zip").write_bytes(b"")
    (tmp_path / "model.zip").write_bytes(b"")
    (tmp_path / "summary.json").write_text(json.dumps({"timesteps": 450000}))
    assert [s for s, _ in run_checkpoints(tmp_path, every=100000, since=250000)] == [
        300000, 400000, 450000]
    assert [s for s, _ in run_checkpoints(tmp_path, every=200000, since=200000)] == [
        200000, 400000, 450000]
    with pytest.raises(ValueError, match="no checkpoints at 500000 steps or later"):
        run_checkpoints(tmp_path, every=100000, since=500000)
    with pytest.raises(ValueError, match="since must be >= 0 env steps, got -1"):
        run_checkpoints(tmp_path, every=100000, since=-1)


def test_table_gives_each_settings_success_where_the_protocol_has_several():
    scores = [CheckpointScore(5900000, 200, 131, (0.587, 0.717), "c0",
                              {"labs": 0.81, "rocky": 0.50}),
              CheckpointScore(6000000, 200, 130, (0.582, 0.713), "c1",
                              {"labs": 0.83, "rocky": 0.47})]
    lines = markdown({"run_a": scores}, "validation-families").splitlines()
    assert lines[0] == ("| run | env steps | labs | rocky | validation-families: success % "
                        "[95% CI] | episodes |")
    assert lines[1] == "|---|---:|---:|---:|---:|---:|"
    assert lines[2] == "| run_a | 5,900,000 | 81 | 50 | 66 [59, 72] | 131/200 |"
    assert lines[3] == "| run_a | 6,000,000 | 83 | 47 | 65 [58, 71] | 130/200 |"
