"""Faults around the process pool: a killed worker, signals to the main process, Ctrl-C
while workers start, Ray addresses that are not Ray, broken ``--import`` modules. Every
run must end (never hang) with its finished work and at most one error line."""

import http.server
import json
import os
import signal
import subprocess
import sys
import threading
import time

import psutil
import pytest

from homing_train.pool import Stopped, WorkerDiedError, pool_results

KILL_SELF = "__import__('os').kill(__import__('os').getpid(), 9)"


def _kill_once(marker) -> str:
    """An item (for ``eval``) that kills its worker the first time it runs, else 7."""
    return (f"7 if __import__('os').path.exists({str(marker)!r}) else "
            f"(open({str(marker)!r}, 'w').close(), {KILL_SELF})")


def test_a_worker_killed_once_costs_nothing(tmp_path):
    items = ["1", "2 * 3", _kill_once(tmp_path / "killed"), "4", "5"]
    assert sorted(pool_results(eval, items, 2)) == [(0, 1), (1, 6), (2, 7), (3, 4), (4, 5)]
    assert (tmp_path / "killed").exists()


def test_a_worker_killed_every_time_ends_with_an_error_naming_the_items():
    items = ["1", KILL_SELF, "3"]
    finished = []
    with pytest.raises(WorkerDiedError, match=r"killed by SIGKILL.*, 2 times in a row; "
                                              r"\d not finished: .*item 1") as err:
        for i, result in pool_results(eval, items, 2, name=lambda s: f"item {items.index(s)}"):
            finished.append(i)
    assert "item 1" in err.value.lost and not set(finished) & {1}


def test_a_task_error_and_an_initializer_error_are_raised_as_themselves():
    with pytest.raises(ZeroDivisionError):
        list(pool_results(eval, ["1", "1 / 0", "3"], 2))
    with pytest.raises(ValueError, match="invalid literal"):
        list(pool_results(eval, ["1", "2"], 2, initializer=int, initargs=("x",)))


def test_more_workers_than_the_machine_can_use_are_refused_before_any_starts():
    cores = os.cpu_count()
    with pytest.raises(ValueError, match=f"from 1 to {4 * cores} here .*{cores} cores"):
        next(pool_results(eval, ["1"] * 2, 4 * cores + 1))
    assert _workers_of(os.getpid()) == []


def _workers_of(pid: int) -> list[psutil.Process]:
    """The spawned pool workers among ``pid``'s children."""
    return [c for c in psutil.Process(pid).children()
            if "spawn_main" in " ".join(c.cmdline())]


@pytest.fixture
def sighup_handled():
    """SIGHUP handled (by doing nothing) in this test run, whatever it was before: the
    pool leaves a SIGHUP that a run ignores (``nohup``) ignored."""
    previous = signal.signal(signal.SIGHUP, lambda signum, frame: None)
    yield
    signal.signal(signal.SIGHUP, previous)


def test_sighup_ends_the_pool_as_ctrl_c_does(sighup_handled):
    """SIGHUP (a closed terminal) or SIGTERM to the main process while a pool runs raises
    :class:`Stopped` there (exit status 128 + the signal) and ends the workers."""
    threading.Timer(3.0, os.kill, (os.getpid(), signal.SIGHUP)).start()
    with pytest.raises(Stopped) as stopped:
        list(pool_results(eval, ["__import__('time').sleep(60)"] * 2, 2))
    assert stopped.value.status == 128 + signal.SIGHUP
    assert _workers_of(os.getpid()) == []


def test_workers_end_when_the_main_process_is_killed():
    """``kill -9`` of the main process leaves no worker waiting for tasks for ever."""
    main = subprocess.Popen([sys.executable, "-c", "from homing_train.pool import "
                             "pool_results; list(pool_results(eval, "
                             "['__import__(\"time\").sleep(60)'] * 2, 2))"])
    try:
        _wait_for(lambda: len(_workers_of(main.pid)) == 2, main, timeout=60)
        workers = _workers_of(main.pid)
        main.kill()
        main.wait()
        gone, alive = psutil.wait_procs(workers, timeout=30)
    finally:
        main.kill()
    assert alive == []


def test_a_hangup_that_the_run_ignores_stays_ignored():
    """Under ``nohup`` (SIGHUP ignored) a closed terminal must not stop the run."""
    from homing_train.pool import stop_on_signals

    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with stop_on_signals():
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            assert signal.getsignal(signal.SIGTERM) not in (signal.SIG_DFL, signal.SIG_IGN)
    finally:
        signal.signal(signal.SIGHUP, previous)


EVAL = [sys.executable, "-m", "homing_train.harness.eval_command", "--policy", "warping",
        "--quiet", "--env-kwargs",
        '{"panorama_shape": [16, 64], "max_episode_steps": 120}']


def _start(tmp_path, episodes: int, workers: int = 2,
           **popen) -> tuple[subprocess.Popen, str]:
    out = str(tmp_path / "w.json")
    process = subprocess.Popen([*EVAL, "--episodes", str(episodes), "--workers", str(workers),
                                "--out", out],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               **popen)
    return process, str(tmp_path / "w.episodes.jsonl")


def _wait_for(condition, process: subprocess.Popen, timeout: float = 240.0) -> None:
    """Poll ``condition()`` until true; fail if ``process`` ends first or it takes
    ``timeout`` seconds."""
    end = time.monotonic() + timeout
    while not condition():
        assert process.poll() is None, process.communicate()[1][-2000:]
        assert time.monotonic() < end, "the condition never came"
        time.sleep(0.1)


def _records(stream: str) -> int:
    """Finished episodes in a stream (its first line is the settings)."""
    if not os.path.exists(stream):
        return 0
    with open(stream) as f:
        return max(sum(1 for _ in f) - 1, 0)


@pytest.mark.slow
def test_killing_a_worker_of_homing_eval_loses_no_episode(tmp_path):
    """The reproducer: ``kill -9`` of one spawned worker (as the out-of-memory killer
    would) mid-run. The run used to wait for ever at N-1/N; now it ends with every
    episode, the records those of a run without a kill."""
    from homing_train.harness.evaluate import evaluate

    process, stream = _start(tmp_path, 16)
    try:
        _wait_for(lambda: _records(stream) >= 1, process)
        _workers_of(process.pid)[0].kill()
        _, err = process.communicate(timeout=300)
    finally:
        process.kill()
    assert process.returncode == 0, err[-2000:]
    killed = json.loads((tmp_path / "w.json").read_text())["episodes"]
    alone = evaluate("warping", episodes=16, env_kwargs={"panorama_shape": [16, 64],
                                                         "max_episode_steps": 120},
                     progress=False)
    strip = lambda episodes: [{k: v for k, v in e.items() if k != "wall_time"}  # noqa: E731
                              for e in episodes]
    assert strip(killed) == strip(alone.to_dict()["episodes"])


@pytest.mark.slow
@pytest.mark.parametrize("workers", [2, 1])
def test_sigterm_to_homing_eval_ends_it_with_one_line_and_no_worker_traceback(tmp_path,
                                                                               workers):
    """SIGTERM to the main process: it used to die at once, its orphaned workers then
    printing tracebacks into the closed pipe; now it ends the pool, keeps the finished
    episodes and says so in one line (status 143), with or without workers."""
    process, stream = _start(tmp_path, 40, workers)
    try:
        _wait_for(lambda: _records(stream) >= 1, process)
        workers = _workers_of(process.pid)
        process.terminate()
        _, err = process.communicate(timeout=120)        # until the workers close stderr
    finally:
        process.kill()
    assert process.returncode == 128 + signal.SIGTERM, err[-2000:]
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith(
        "homing-eval: interrupted"), err[-2000:]
    assert _records(stream) >= 1
    assert not any(w.is_running() and w.status() != psutil.STATUS_ZOMBIE for w in workers)


@pytest.mark.slow
def test_ctrl_c_while_the_workers_start_prints_no_worker_traceback(tmp_path):
    """Ctrl-C in a terminal signals the whole process group; workers still importing
    used to print a KeyboardInterrupt traceback each."""
    process, _ = _start(tmp_path, 40, start_new_session=True)   # cannot end before the signal
    try:
        _wait_for(lambda: len(_workers_of(process.pid)) == 2, process)
        time.sleep(0.5)                                  # the workers are importing
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=120)
    finally:
        process.kill()
    assert process.returncode == 130, err[-2000:]
    assert "Traceback" not in err, err[-2000:]


@pytest.fixture
def http_server():
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                             http.server.BaseHTTPRequestHandler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"127.0.0.1:{server.server_address[1]}"
    server.shutdown()


def test_a_ray_address_that_is_not_ray_is_refused_in_seconds(http_server):
    """An HTTP server, or a server that accepts and stays silent, used to keep
    ``ray.init`` retrying for minutes."""
    from homing_train.harness.evaluate import check_ray_address

    with pytest.raises(ValueError, match="something answers there, but not as Ray does"):
        check_ray_address(http_server, timeout=2.0)
    # the silent server: test_evaluate.py's test_a_ray_address_where_nothing_answers...


@pytest.mark.slow
def test_a_ray_cluster_passes_the_address_check():
    import ray

    from homing_train.harness.evaluate import check_ray_address

    ray.init(address="local", num_cpus=1, include_dashboard=False, log_to_driver=False)
    try:
        check_ray_address(ray.get_runtime_context().gcs_address)
    finally:
        ray.shutdown()


@pytest.mark.parametrize("source, words", [
    ("def broken(:\n", "SyntaxError"),
    ("raise RuntimeError('the lab is closed')\n", "RuntimeError: the lab is closed"),
])
def test_a_broken_import_module_is_one_error_line(tmp_path, monkeypatch, capsys, source,
                                                  words):
    from homing_train.harness import eval_command

    name = f"broken_{abs(hash(source))}"
    (tmp_path / f"{name}.py").write_text(source)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as end:
        eval_command.main(["--import", name, "--policy", "random", "--out", "r.json"])
    err = capsys.readouterr().err
    assert end.value.code == 2
    assert f"error: --import {name!r}: importing it failed: {words}" in err
