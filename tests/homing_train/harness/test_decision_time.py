"""The decision-time benchmark: every method timed on the same views against warping."""

import pytest

from homing_train.harness.decision_time import decision_times, main


def test_each_method_is_timed_on_the_same_views_against_warping(capsys):
    rows = decision_times(["min-warping", "did"], worlds=1, calls=3,
                          panorama_shape=(16, 128))        # min-warping: 128 columns
    assert [r.method for r in rows] == ["warping", "min-warping", "did"]
    assert all(r.calls == 3 and 0 < r.median <= r.p90 for r in rows)
    assert rows[0].ratio == 1.0
    assert rows[1].ratio == pytest.approx(rows[1].median / rows[0].median)


@pytest.mark.parametrize("kwargs, message", [
    ({"methods": ["nope"]}, r"unknown methods \['nope'\]"),
    ({"methods": ["did"], "worlds": 0}, r"worlds must be an integer >= 1, got 0"),
    ({"methods": ["did"], "calls": 1.5}, r"calls must be an integer >= 1, got 1.5"),
])
def test_bad_arguments_are_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        decision_times(**kwargs)


def test_the_command_prints_the_table_and_writes_the_rows(tmp_path, capsys):
    import json

    out = tmp_path / "times.json"
    assert main(["--methods", "did", "--worlds", "1", "--calls", "2", "--shape", "16", "64",
                 "--json", str(out)]) == 0
    assert "| did | 2 |" in capsys.readouterr().out
    assert [r["method"] for r in json.loads(out.read_text())] == ["warping", "did"]
