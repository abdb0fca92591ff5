"""Faults around the commands' outputs: every ``--out`` checked before any work, one
writer per output, an interrupted suite that keeps its episodes and resumes, ``--resume``
that reads only sound streams, and no silent nonsense (an empty result, a method that
cannot run)."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest

from homing_train.harness import compare as compare_cli
from homing_train.harness import eval_command as eval_cli
from homing_train.harness import field as field_cli
from homing_train.harness import suite as suite_cli
from homing_train.harness.evaluate import read_stream, stream_path

TINY = json.dumps({"panorama_shape": [16, 64], "max_episode_steps": 20})
EVAL = ["--policy", "random", "--episodes", "2", "--quiet", "--env-kwargs", TINY]


def exit_of(main, argv, capsys) -> tuple[int, str]:
    """The exit status of a command's ``main`` and the last line it wrote to stderr."""
    try:
        code = main(argv)
    except SystemExit as end:
        code = end.code
    err = capsys.readouterr().err.strip().splitlines()
    return code, err[-1] if err else ""


# -- every --out checked before any work ----------------------------------------------------
@pytest.mark.parametrize("main,argv", [
    (eval_cli.main, [*EVAL, "--out", ""]),
    (eval_cli.main, [*EVAL, "--out", "{tmp}"]),                       # a folder
    (eval_cli.main, [*EVAL, "--out", "{tmp}/file/r.json"]),           # a file on the way
    (eval_cli.main, [*EVAL, "--out", "/proc/x/r.json"]),
    (eval_cli.main, [*EVAL, "--out", "{tmp}/r", "--protocol", "yukim"]),   # no extension
    (field_cli.main, ["--policy", "warping", "--no-return", "--out", "{tmp}/f.txt"]),
    (field_cli.main, ["--policy", "warping", "--no-return", "--out", "{tmp}/file/f.png"]),
    (suite_cli.main, ["--methods", "oracle", "--out", "{tmp}/file"]),
    (compare_cli.main, ["{tmp}/r.json", "--out", "{tmp}/file"]),
])
def test_an_unusable_out_ends_the_command_before_any_work(main, argv, tmp_path, capsys,
                                                          monkeypatch):
    (tmp_path / "file").write_text("x")
    monkeypatch.chdir(tmp_path)
    before = sorted(os.listdir(tmp_path))
    code, last = exit_of(main, [a.replace("{tmp}", str(tmp_path)) for a in argv], capsys)
    assert code == 2 and "error:" in last
    assert sorted(os.listdir(tmp_path)) == before        # no stream, no folder, no picture


# -- one writer per output ------------------------------------------------------------------
@pytest.fixture
def held_lock():
    """Hold the lock of an output in a child process (as a second run would)."""
    children = []

    def hold(path: str) -> None:
        child = subprocess.Popen(
            [sys.executable, "-c", "import sys; from homing_gym.outputs import OutputLock; "
             f"OutputLock({path!r}).acquire(); print('held', flush=True); sys.stdin.read()"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        children.append(child)
        assert child.stdout.readline().strip() == "held"

    yield hold
    for child in children:
        child.stdin.close()
        child.wait(timeout=30)


def test_a_second_homing_eval_on_one_out_is_refused_at_start(tmp_path, capsys, held_lock):
    out = str(tmp_path / "r.json")
    held_lock(out)
    code, last = exit_of(eval_cli.main, [*EVAL, "--seed", "7", "--out", out], capsys)
    assert code == 2 and "another run" in last and str(os.getpid()) not in last
    assert not os.path.exists(out) and not os.path.exists(stream_path(out))


def test_a_second_writer_of_an_episode_stream_is_refused(tmp_path, capsys, held_lock):
    # a suite and an eval that share a stream (results/oracle.episodes.jsonl) cannot mix it
    held_lock(str(tmp_path / "suite" / "oracle.episodes.jsonl"))
    code, last = exit_of(suite_cli.main, ["--methods", "oracle", "--episodes", "1",
                                          "--workers", "1", "--env-kwargs", TINY,
                                          "--out", str(tmp_path / "suite")], capsys)
    assert code == 2 and "another run" in last
    assert not (tmp_path / "suite" / "oracle.episodes.jsonl").exists()


def test_a_suite_folder_has_one_writer(tmp_path, capsys, held_lock):
    held_lock(str(tmp_path / "suite"))
    code, last = exit_of(suite_cli.main, ["--methods", "oracle", "--out",
                                          str(tmp_path / "suite")], capsys)
    assert code == 2 and "another run" in last


# -- an interrupted plain suite keeps its episodes and resumes ---------------------------------
def _stream_lines(path) -> int:
    try:
        with open(path) as f:
            return sum(1 for line in f if line.endswith("\n"))
    except FileNotFoundError:
        return 0


@pytest.mark.slow                      # about 25 s: two runs of a two-method suite
def test_ctrl_c_in_a_plain_suite_keeps_the_finished_episodes_and_resume_runs_the_rest(
        tmp_path):
    # random runs each episode to the step cap: several seconds of work left when the
    # first oracle episode is in, so the signal finds the suite running on a busy machine
    out = tmp_path / "suite"
    argv = [sys.executable, "-m", "homing_train.harness.suite", "--methods", "oracle",
            "random", "--episodes", "6", "--workers", "1", "--env-kwargs",
            json.dumps({"panorama_shape": [16, 64], "max_episode_steps": 400}),
            "--out", str(out)]
    run = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stream = out / "oracle.episodes.jsonl"
    deadline = time.monotonic() + 120
    while _stream_lines(stream) < 2 and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)                 # the settings and one finished episode
    run.send_signal(signal.SIGINT)
    _, err = run.communicate(timeout=60)
    assert run.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err.strip().splitlines()[-1]
    kept = read_stream(str(stream), json.loads(stream.read_text().splitlines()[0]))
    assert kept                                          # the finished episodes stayed
    resumed = subprocess.run([*argv, "--resume"], capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    episodes = json.loads((out / "oracle.json").read_text())["episodes"]
    assert [e["seed"] for e in episodes] == list(range(6))
    for seed, record in kept.items():                    # kept, not run again
        assert episodes[seed]["wall_time"] == record.wall_time
    assert (out / "random.json").exists() and (out / "table.md").exists()


# -- --resume reads only sound streams ---------------------------------------------------------
@pytest.fixture(scope="module")
def finished_eval(tmp_path_factory):
    """A finished two-episode homing-eval: its result and its stream's lines."""
    out = tmp_path_factory.mktemp("eval") / "r.json"
    assert eval_cli.main([*EVAL, "--out", str(out)]) == 0
    return out, open(stream_path(str(out))).read().splitlines()


def _with_field(line: str, **changes) -> str:
    return json.dumps(json.loads(line) | changes)


def _lacking(line: str, key: str) -> str:
    doc = json.loads(line)
    del doc[key]
    return json.dumps(doc)


CRAFTED = {   # name: (the stream's lines from the finished one's, the line named)
    "torn middle line": (lambda h, a, b: [h, a[:40], b], 2),
    "steps as text": (lambda h, a, b: [h, _with_field(a, steps="20"), b], 2),
    "a missing field": (lambda h, a, b: [h, a, _lacking(b, "path_length")], 3),
    "NaN path length": (lambda h, a, b: [h, a.replace('"path_length": ', '"path_length": NaN, "x": '), b], 2),
    "negative steps": (lambda h, a, b: [h, _with_field(a, steps=-3), b], 2),
    "negative wall time": (lambda h, a, b: [h, a, _with_field(b, wall_time=-1.0)], 3),
    "success as a number": (lambda h, a, b: [h, _with_field(a, success=1), b], 2),
    "a seed twice, other content": (lambda h, a, b: [h, a, _with_field(a, steps=3), b], 3),
    "other settings": (lambda h, a, b: [_with_field(h, policy="oracle"), a, b], 1),
}


@pytest.mark.parametrize("case", sorted(CRAFTED))
def test_resume_refuses_an_unsound_stream_naming_file_and_line(case, finished_eval, tmp_path,
                                                              capsys):
    result, lines = finished_eval
    craft, line = CRAFTED[case]
    out = tmp_path / "r.json"
    with open(stream_path(str(out)), "w") as f:
        f.write("\n".join(craft(*lines)) + "\n")
    code, last = exit_of(eval_cli.main, [*EVAL, "--out", str(out), "--resume"], capsys)
    assert code == 2, last
    assert f"{stream_path(str(out))} line {line}:" in last
    assert not out.exists()                              # nothing was run


def test_resume_drops_a_torn_last_line_and_leaves_a_sound_stream(finished_eval, tmp_path,
                                                                 capsys):
    result, lines = finished_eval
    out = tmp_path / "r.json"
    stream = stream_path(str(out))
    with open(stream, "w") as f:
        f.write("\n".join(lines[:2]) + "\n" + lines[2][:50])     # killed mid-write
    assert eval_cli.main([*EVAL, "--out", str(out), "--resume"]) == 0
    episodes = json.loads(out.read_text())["episodes"]
    first = json.loads(lines[1])
    assert episodes[0]["wall_time"] == first["wall_time"]       # kept
    assert sorted(read_stream(stream, json.loads(lines[0]))) == [0, 1]   # reads whole again


def test_a_repeated_identical_line_is_harmless(finished_eval, tmp_path):
    _, lines = finished_eval
    path = tmp_path / "r.episodes.jsonl"
    path.write_text("\n".join([*lines, lines[1]]) + "\n")
    assert sorted(read_stream(str(path), json.loads(lines[0]))) == [0, 1]


# -- no silent nonsense -------------------------------------------------------------------------
@pytest.mark.parametrize("edit,says", [
    (lambda doc: doc | {"episodes": []}, "no episodes"),
    (lambda doc: doc | {"episodes": doc["episodes"][:1]}, "summary"),
    (lambda doc: doc | {"episodes": [doc["episodes"][0] | {"spl": 7}, doc["episodes"][1]]},
     "spl"),
])
def test_compare_refuses_a_result_whose_episodes_do_not_back_its_summary(
        edit, says, finished_eval, tmp_path, capsys):
    result, _ = finished_eval
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(edit(json.loads(result.read_text()))))
    code, last = exit_of(compare_cli.main, [str(bad), "--out", str(tmp_path / "cmp")], capsys)
    assert code == 2 and says in last and str(bad) in last
    assert not (tmp_path / "cmp" / "table.md").exists()


def test_a_suite_of_methods_that_cannot_run_is_an_error_not_an_empty_table(tmp_path, capsys):
    code, last = exit_of(suite_cli.main, ["--methods", "bearing", "--env-kwargs", TINY,
                                          "--out", str(tmp_path / "s")], capsys)
    assert code == 2 and "bearing cannot run" in last and "lab" in last


def test_a_matrix_of_methods_that_apply_to_no_protocol_is_an_error(tmp_path, capsys):
    code, last = exit_of(suite_cli.main, ["--protocols", "hong1991", "--methods", "multires",
                                          "--out", str(tmp_path / "m")], capsys)
    assert code == 2 and "multires cannot run" in last and "WorkLocations" in last
    assert not (tmp_path / "m" / "matrix.json").exists()


def test_a_method_that_cannot_run_in_some_protocols_is_left_out_with_a_note(capsys):
    from homing_train.harness.matrix import applicable

    assert applicable(["multires", "oracle"], {"oracle"}, lambda: "protocol hong1991") == [
        "oracle"]
    assert "left out multires" in capsys.readouterr().out


def test_eval_says_why_a_method_cannot_run_in_a_protocol(tmp_path, capsys):
    code, last = exit_of(eval_cli.main, ["--protocol", "hong1991", "--policy", "multires",
                                         "--out", str(tmp_path / "c.json")], capsys)
    assert code == 2 and "cannot run in protocol 'hong1991'" in last
    assert "obs_keys" not in last
