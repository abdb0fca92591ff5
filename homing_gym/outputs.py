"""The one owner of the files the commands write: paths checked before work starts, a
lock against a second writer, and atomic writes (a temporary file in the same folder,
then ``os.replace``), so an interrupt, a kill or a full disk leaves the old file or the
new one, never a torn one."""

from __future__ import annotations

import argparse
import contextlib
import errno
import fcntl
import os
import tempfile
from collections.abc import Iterator


class OutputBusyError(ValueError):
    """Another process is writing the same output; the message names it and its pid."""


def _writable(folder: str) -> bool:
    """Whether a file can be made in ``folder`` (tried: permissions alone say yes to root
    in ``/proc`` or on a read-only mount)."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".probe.", dir=folder)
    except OSError:
        return False
    os.close(fd)
    os.remove(probe)
    return True


def _nearest_existing(path: str) -> str:
    """The path itself or its nearest existing ancestor."""
    while not os.path.exists(path):
        parent = os.path.dirname(path)
        if parent == path:
            break
        path = parent
    return path


def checked_output_file(path: str, option: str = "--out") -> str:
    """``path`` as an absolute path, once it is known that a file can be written there;
    ``ValueError`` naming ``option`` and ``path`` otherwise (empty, a folder, a file where
    a folder is needed on the way, or a folder this user cannot write). Call it before any
    work starts."""
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise ValueError(f"{option} {path!r}: expected a file path, got an empty one")
    full = os.path.abspath(os.fspath(path))
    if os.path.isdir(full):
        raise ValueError(f"{option} {path!r} is a folder; expected a file path")
    existing = _nearest_existing(os.path.dirname(full))
    if not os.path.isdir(existing):
        raise ValueError(f"{option} {path!r}: {existing!r} is a file, not a folder")
    if not _writable(existing):
        raise ValueError(f"{option} {path!r}: cannot write in {existing!r} (permission)")
    if os.path.exists(full) and not os.access(full, os.W_OK):
        raise ValueError(f"{option} {path!r}: the file exists and cannot be written")
    return full


def checked_output_dir(path: str, option: str = "--out") -> str:
    """Like :func:`checked_output_file` for a folder the command fills: ``path`` must be
    a folder or not exist, with a writable nearest existing ancestor."""
    if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
        raise ValueError(f"{option} {path!r}: expected a folder path, got an empty one")
    full = os.path.abspath(os.fspath(path))
    if os.path.exists(full) and not os.path.isdir(full):
        raise ValueError(f"{option} {path!r} is a file; expected a folder")
    existing = _nearest_existing(full)
    if not os.path.isdir(existing):
        raise ValueError(f"{option} {path!r}: {existing!r} is a file, not a folder")
    if not _writable(existing):
        raise ValueError(f"{option} {path!r}: cannot write in {existing!r} (permission)")
    return full


def _argument(check):
    """An argparse ``type`` that runs ``check`` on the text and keeps the text, so a bad
    output ends the command at parse time (exit status 2, one ``error:`` line), before
    any work."""
    def checked(text: str) -> str:
        try:
            check(text, "path")
        except ValueError as err:
            raise argparse.ArgumentTypeError(str(err)) from None
        return text
    checked.__name__ = check.__name__.removeprefix("checked_")   # argparse's name for it
    return checked


#: ``type=`` of an option that names an output file (:func:`checked_output_file`).
output_file_argument = _argument(checked_output_file)
#: ``type=`` of an option that names an output folder (:func:`checked_output_dir`).
output_dir_argument = _argument(checked_output_dir)


@contextlib.contextmanager
def atomic_path(path: str) -> Iterator[str]:
    """A temporary path beside ``path`` to write to; on a clean exit it is synced and
    renamed over ``path`` in one step, on an error it is removed and ``path`` untouched."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.", suffix=".tmp", dir=folder)
    os.close(fd)
    try:
        yield tmp
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


def write_text_atomic(path: str, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, "w") as f:
        f.write(text)


def write_bytes_atomic(path: str, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (:func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        f.write(data)


def save_figure(fig, path, **savefig_kwargs) -> None:
    """Save the matplotlib figure ``fig`` to ``path`` atomically (:func:`atomic_path`),
    in the format its extension names (``savefig_kwargs``: ``dpi``, ``bbox_inches``...)."""
    path = os.fspath(path)
    fmt = os.path.splitext(path)[1].lstrip(".").lower() or None
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **savefig_kwargs)


def lock_path(path: str) -> str:
    """The lock file of an output: ``.NAME.lock`` beside it."""
    full = os.path.abspath(path)
    return os.path.join(os.path.dirname(full), f".{os.path.basename(full)}.lock")


class OutputLock:
    """An exclusive, non-blocking lock on an output path, held by this process until
    :meth:`release` (or the end of a ``with`` block, or the process). A second writer
    gets :class:`OutputBusyError` at once, naming the path and the holder's pid; a lock
    left by a killed process is free again (the kernel drops it with the process)."""

    def __init__(self, path: str):
        self.path = os.path.abspath(path)
        self.file = lock_path(self.path)
        self._fd: int | None = None

    def acquire(self) -> OutputLock:
        os.makedirs(os.path.dirname(self.file), exist_ok=True)
        while True:
            fd = os.open(self.file, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as err:
                holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
                os.close(fd)
                if err.errno in (errno.EAGAIN, errno.EACCES):
                    raise OutputBusyError(
                        f"{self.path!r} is being written by another run (pid {holder}); "
                        f"wait for it, or choose another output") from None
                raise
            try:                      # the file may have been removed by its last holder
                same = os.stat(self.file).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return self

    def release(self) -> None:
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            os.remove(self.file)
        os.close(self._fd)
        self._fd = None

    def __enter__(self) -> OutputLock:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()
