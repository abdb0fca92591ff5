"""The commands' one process pool: spawned workers, and no hang when one of them dies.

A worker that dies (``kill -9``, the out-of-memory killer, a crash in native code) breaks
the pool at once (:class:`concurrent.futures.ProcessPoolExecutor`), where a
``multiprocessing.Pool`` would wait for its task for ever. The items not finished then
run again in a fresh pool, once by default; lost a second time, they end the run with
:class:`WorkerDiedError`, which names them and how the worker ended. Results already
handed out stay valid: items are seeded, so a rerun gives the same result.

Workers ignore Ctrl-C from the moment they start, importing included (the main process
ends the pool), and end with the main process, even a killed one. SIGTERM or SIGHUP to
the main process while a pool runs ends it as Ctrl-C does (:class:`Stopped`), so that
no worker is left running to print tracebacks into a closed pipe.
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing as mp
import os
import signal
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import connection
from typing import Any, NoReturn

#: The most worker processes a pool starts per CPU core.
WORKERS_PER_CORE = 4

_FAILED: list[BaseException] = []          # in a worker: its initializer's error


class WorkerDiedError(RuntimeError):
    """A worker process died and the items it left were lost again in a fresh pool."""

    def __init__(self, lost: Sequence[str], ending: str, pools: int):
        self.lost = list(lost)
        shown = ", ".join(self.lost[:20]) + (", ..." if len(self.lost) > 20 else "")
        super().__init__(f"a worker process died ({ending}), {pools} times in a row; "
                         f"{len(self.lost)} not finished: {shown}")


class Stopped(KeyboardInterrupt):
    """SIGTERM or SIGHUP to the main process (in :func:`stop_on_signals`), raised as
    Ctrl-C's ``KeyboardInterrupt`` is; ``status`` is the exit status for it, 128 + the
    signal."""

    def __init__(self, signum: int):
        super().__init__(f"stopped by {signal.Signals(signum).name}")
        self.status = 128 + signum


def end_stopped_command(parser: argparse.ArgumentParser, stop: BaseException,
                        kept: str) -> NoReturn:
    """End a command that ``stop`` ended with one line saying so and ``kept`` (what
    became of its work): status 1 for :class:`WorkerDiedError`, 130 for Ctrl-C, 128 +
    the signal for :class:`Stopped`."""
    if isinstance(stop, WorkerDiedError):
        parser.exit(1, f"{parser.prog}: error: {stop}; {kept}\n")
    parser.exit(getattr(stop, "status", 128 + signal.SIGINT),
                f"{parser.prog}: interrupted; {kept}\n")


def _start_worker(initializer: Callable[..., None] | None, initargs: tuple) -> None:
    """A worker ignores Ctrl-C (inherited from its start already) and keeps its
    initializer's error for its tasks to raise: an executor whose initializer raises
    is broken, which would read as a worker death. It ends when the main process does,
    even by SIGKILL, rather than wait for tasks for ever."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = mp.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with, args=(parent.sentinel,), daemon=True).start()
    if initializer is not None:
        try:
            initializer(*initargs)
        except Exception as err:  # noqa: BLE001  (any failure: raised by the tasks)
            _FAILED.append(err)


def _exit_with(parent_sentinel: int) -> None:
    """End this worker at once when the process behind ``parent_sentinel`` ends."""
    connection.wait([parent_sentinel])
    os._exit(1)


def _call(fn: Callable[[Any], Any], item: Any) -> Any:
    if _FAILED:
        raise _FAILED[0]
    return fn(item)


@contextlib.contextmanager
def _signals(handlers: dict[int, Any]) -> Iterator[None]:
    """``handlers`` installed for the block (main thread only; elsewhere nothing); a
    signal a user set to ignore (``nohup``) stays ignored."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.getsignal(s) for s in handlers}
    for s, handler in handlers.items():
        if previous[s] is not signal.SIG_IGN:
            signal.signal(s, handler)
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def _raise_stopped(signum: int, frame) -> None:
    raise Stopped(signum)


def stop_on_signals() -> contextlib.AbstractContextManager:
    """SIGTERM and SIGHUP raise :class:`Stopped` in the block (a ``with`` block or a
    decorated function), so that it ends as on Ctrl-C, keeping what finished."""
    return _signals({signal.SIGTERM: _raise_stopped, signal.SIGHUP: _raise_stopped})


def _ending(exit_codes: Sequence[int | None]) -> str:
    """How the dead worker ended, from every worker's exit code (the pool ends the
    others with SIGTERM)."""
    odd = [c for c in exit_codes if c not in (None, 0, -signal.SIGTERM)]
    code = odd[0] if odd else -signal.SIGTERM
    if code > 0:
        return f"it exited with status {code}"
    try:
        name = signal.Signals(-code).name
    except ValueError:
        name = f"signal {-code}"
    return f"killed by {name}" + (", as the out-of-memory killer does"
                                  if code == -signal.SIGKILL else "")


def _one_pool(fn: Callable[[Any], Any], items: Sequence[Any], todo: list[int],
              workers: int, initializer, initargs: tuple):
    """Yield ``(index, result)`` for the items ``todo`` from one fresh pool; return the
    indices lost to a dead worker and how it ended (``[]``, ``""`` if none was)."""
    executor = ProcessPoolExecutor(min(workers, len(todo)), mp_context=mp.get_context("spawn"),
                                   initializer=_start_worker, initargs=(initializer, initargs))
    futures: dict = {}
    given: set[int] = set()
    lost: list[int] = []
    finished = False
    try:
        # workers are spawned by the first submits: they inherit SIGINT ignored
        with _signals({signal.SIGINT: signal.SIG_IGN}):
            for i in todo:
                try:
                    futures[executor.submit(_call, fn, items[i])] = i
                except BrokenProcessPool:        # a worker died already
                    break
        for future in as_completed(futures):
            if isinstance(future.exception(), BrokenProcessPool):
                wait(futures)            # the pool sets every unfinished future at once
                break
            given.add(futures[future])
            yield futures[future], future.result()       # a task's error is raised here
        for future, i in futures.items():    # after a break: the finished and the lost
            if i in given:
                continue
            if isinstance(future.exception(), BrokenProcessPool):
                lost.append(i)
            else:
                yield i, future.result()
        lost += todo[len(futures):]
        finished = True
    finally:
        processes = list((executor._processes or {}).values())  # noqa: SLF001
        if not finished:                 # an error, Ctrl-C or the caller stopped early
            for process in processes:
                process.terminate()
        executor.shutdown(wait=True, cancel_futures=True)
    return lost, _ending([p.exitcode for p in processes]) if lost else ""


def pool_results(fn: Callable[[Any], Any], items: Sequence[Any], workers: int,
                 initializer: Callable[..., None] | None = None, initargs: tuple = (),
                 retries: int = 1, name: Callable[[Any], str] = repr
                 ) -> Iterator[tuple[int, Any]]:
    """``(index, fn(items[index]))`` for every item, in finishing order, from
    ``min(workers, len(items))`` spawned processes that each run
    ``initializer(*initargs)`` first (if it raises, their tasks raise its error);
    ``workers`` is at most :data:`WORKERS_PER_CORE` per CPU core. ``fn`` and the items
    must pickle. Items lost to a dead worker run again in a fresh pool, up
    to ``retries`` times; then :class:`WorkerDiedError` names them (by ``name(item)``).
    A task's own error is raised as itself and ends the pool, as Ctrl-C does; SIGTERM
    and SIGHUP raise :class:`Stopped` while the pool runs. Close the generator
    (``contextlib.closing``) to end the pool when stopping early."""
    cores = os.cpu_count() or 1
    if not 1 <= workers <= WORKERS_PER_CORE * cores:
        raise ValueError(f"workers must be from 1 to {WORKERS_PER_CORE * cores} here "
                         f"({WORKERS_PER_CORE} per CPU core, {cores} cores: more only share "
                         f"the cores, each holding its own env in memory), got {workers}")
    todo, pools, ending = list(range(len(items))), 0, ""
    with stop_on_signals():
        while todo:
            if pools > retries:
                raise WorkerDiedError([name(items[i]) for i in todo], ending, pools)
            todo, ending = yield from _one_pool(fn, items, todo, workers, initializer,
                                                initargs)
            pools += 1
