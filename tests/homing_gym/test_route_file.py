"""Routes from files: CSV, NPY and JSON rows of x, y[, yaw]; bad files refused with the
file and the point named, and a .npy file never unpickled."""

import json
import math
import os

import numpy as np
import pytest

from homing_gym.tasks.route_file import MAX_ROUTE_POINTS, load_route
from homing_gym.tasks.route_following import RouteFollowingTask

#: A route in the arena's free floor: start, then two targets; yaw: the direction of travel.
POINTS = [(0.5, -0.8), (0.5, -0.3), (0.0, -0.3)]


def test_a_csv_file_with_header_comments_and_blank_lines(tmp_path):
    path = tmp_path / "route.csv"
    path.write_text("x, y, yaw\n# surveyed 2026-11-27\n0.5,-0.8,0\n\n0.5, -0.3, 0.25\n"
                    "0.0,-0.3,1.5\n")
    np.testing.assert_array_equal(load_route(str(path)),
                                  [[0.5, -0.8, 0], [0.5, -0.3, 0.25], [0.0, -0.3, 1.5]])


def test_an_npy_file_and_a_pathlike(tmp_path):
    path = tmp_path / "route.npy"
    np.save(path, np.array([[0, 0], [1, 2], [3, 4]], dtype=np.int32))
    route = load_route(path)                        # a pathlib.Path
    assert route.dtype == np.float64
    np.testing.assert_array_equal(route, [[0, 0], [1, 2], [3, 4]])


def test_a_json_file_gives_the_task_its_targets(tmp_path):
    path = tmp_path / "route.json"
    path.write_text(json.dumps([[0.5, -0.8, 0.0], [0.5, -0.3, 0.0], [0.0, -0.3, 1.5]]))
    from_file = RouteFollowingTask(route=str(path))
    from_list = RouteFollowingTask(route=[(0.5, -0.8, 0.0), (0.5, -0.3, 0.0), (0.0, -0.3, 1.5)])
    assert from_file.n_targets == 2
    np.testing.assert_array_equal(from_file.route, from_list.route)


def test_lists_pass_through_unchanged():
    assert load_route(POINTS) is POINTS and load_route(None) is None


def test_an_env_follows_a_route_file(tmp_path):
    import gymnasium as gym

    import homing_gym  # noqa: F401
    path = tmp_path / "route.csv"
    path.write_text("\n".join(",".join(map(str, p)) for p in POINTS))
    env = gym.make("homing_gym/RouteFollowing-v0", route=str(path), scene="arena",
                   start_jitter=(0.0, 0.0))
    _, info = env.reset(seed=0)
    env.close()
    np.testing.assert_allclose(info["start_pose"], (0.5, -0.8, math.pi / 2), atol=1e-9)
    np.testing.assert_allclose(info["home_pose"], (0.0, -0.3, math.pi), atol=1e-9)


def _write(tmp_path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("name, text, message", [
    ("one.csv", "0,0\n", "holds 1 point(s); a route needs at least two"),
    ("empty.json", "[]", "holds 0 point(s)"),
    ("nan.csv", "0,0\n1,nan\n", "point 1 (line 2): expected x, y or x, y, yaw as finite"),
    ("inf.json", "[[0, 0], [1, 1e400]]", "point 1 (item 1)"),
    ("word.csv", "0,0\n1,one\n", "point 1 (line 2)"),
    ("four.csv", "0,0,0,0\n1,1,1,1\n", "point 0 (line 1): expected x, y or x, y, yaw"),
    ("mixed.csv", "0,0\n1,1,0\n", "point 1 (line 2): 3 columns, but point 0 has 2"),
    ("bool.json", "[[0, 0], [true, 1]]", "point 1 (item 1)"),
    ("object.json", '{"route": [[0, 0], [1, 1]]}', "expected a JSON list"),
    ("broken.json", "[[0, 0], [1", "not valid JSON"),
    ("route.txt", "0,0\n1,1\n", "unknown format '.txt'; allowed: .csv, .npy, .json"),
])
def test_bad_route_files_are_refused_naming_the_file_and_point(tmp_path, name, text, message):
    path = _write(tmp_path, name, text)
    with pytest.raises(ValueError) as err:
        load_route(path)
    assert repr(path) in str(err.value) and message in str(err.value)


def test_unreadable_files_and_folders_are_refused(tmp_path):
    (tmp_path / "routes.csv").mkdir()
    binary = tmp_path / "binary.json"
    binary.write_bytes(bytes(range(256)))
    not_npy = tmp_path / "text.npy"
    not_npy.write_text("0,0\n1,1\n")
    for path, message in ((tmp_path / "routes.csv", "is a directory"),
                          (tmp_path / "missing.csv", "cannot read it"),
                          (binary, "cannot read it"),
                          (not_npy, "not a numeric .npy array")):
        with pytest.raises(ValueError, match="route file") as err:
            load_route(str(path))
        assert str(path) in str(err.value) and message in str(err.value), err.value


def test_npy_arrays_of_the_wrong_shape_or_kind(tmp_path):
    for name, array in (("flat.npy", np.zeros(4)), ("text.npy", np.array([["0", "0"]] * 2)),
                        ("wide.npy", np.zeros((3, 4)))):
        np.save(tmp_path / name, array)
        with pytest.raises(ValueError, match=f"{name}.*(shape|x, y or x, y, yaw)"):
            load_route(str(tmp_path / name))


class _Planted:
    """Unpickling this creates a file: what a hostile .npy could do instead."""

    def __init__(self, marker: str):
        self.marker = marker

    def __reduce__(self):
        return (open, (self.marker, "w"))


def test_a_pickled_npy_file_is_refused_and_runs_no_code(tmp_path):
    marker = tmp_path / "pwned"
    path = tmp_path / "route.npy"
    array = np.empty((2, 2), dtype=object)
    array[:] = 0.0
    array[1, 1] = _Planted(str(marker))
    np.save(path, array, allow_pickle=True)
    with pytest.raises(ValueError, match="route.npy.*read without unpickling"):
        load_route(str(path))
    assert not marker.exists()


def test_more_points_than_the_bound_are_refused(tmp_path):
    rows = "\n".join(f"{0.1 * k},0" for k in range(MAX_ROUTE_POINTS + 1))
    path = _write(tmp_path, "long.csv", rows)
    with pytest.raises(ValueError, match=f"more than {MAX_ROUTE_POINTS} points"):
        load_route(path)
    np.save(tmp_path / "long.npy", np.zeros((MAX_ROUTE_POINTS + 1, 2)))
    with pytest.raises(ValueError, match=f"more than {MAX_ROUTE_POINTS} points"):
        load_route(str(tmp_path / "long.npy"))
    assert len(load_route(_write(tmp_path, "most.csv", "\n".join(rows.split("\n")[:-1])))) \
        == MAX_ROUTE_POINTS


def test_the_route_rules_still_apply_to_a_file(tmp_path):
    path = _write(tmp_path, "close.csv", "0,0\n0.01,0\n")
    with pytest.raises(ValueError, match="at least 0.05 m apart"):
        RouteFollowingTask(route=path)
    assert os.path.isfile(path)
