"""Output paths: checked before work, locked against a second writer, written atomically."""

import os
import subprocess
import sys

import pytest

from homing_gym.outputs import (OutputBusyError, OutputLock, checked_output_dir,
                                checked_output_file, save_figure, write_text_atomic)


@pytest.mark.parametrize("bad", ["", "   "])
def test_an_empty_output_is_refused(bad):
    with pytest.raises(ValueError, match="empty"):
        checked_output_file(bad)


def test_a_folder_is_not_an_output_file(tmp_path):
    with pytest.raises(ValueError, match="is a folder"):
        checked_output_file(str(tmp_path))


def test_a_file_on_the_way_is_refused(tmp_path):
    (tmp_path / "f.txt").write_text("x")
    with pytest.raises(ValueError, match="is a file, not a folder"):
        checked_output_file(str(tmp_path / "f.txt" / "r.json"))
    with pytest.raises(ValueError, match="is a file; expected a folder"):
        checked_output_dir(str(tmp_path / "f.txt"))


def test_an_unwritable_place_is_refused():
    with pytest.raises(ValueError, match="cannot write|is a file"):
        checked_output_file("/proc/x/r.json")


def test_a_new_nested_path_is_fine(tmp_path):
    out = tmp_path / "a" / "b" / "r.json"
    assert checked_output_file(str(out)) == str(out)
    assert not (tmp_path / "a").exists()          # checking creates nothing


def test_an_atomic_write_leaves_the_old_file_on_error(tmp_path, monkeypatch):
    path = tmp_path / "r.json"
    write_text_atomic(str(path), "old")
    monkeypatch.setattr(os, "replace", lambda *a: (_ for _ in ()).throw(OSError(28, "full")))
    with pytest.raises(OSError):
        write_text_atomic(str(path), "new")
    assert path.read_text() == "old"
    assert sorted(os.listdir(tmp_path)) == ["r.json"]      # no temporary left


def test_a_second_writer_is_refused_and_the_lock_frees(tmp_path):
    out = str(tmp_path / "r.json")
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from homing_gym.outputs import OutputLock;"
         f"OutputLock({out!r}).acquire(); print('held', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(OutputBusyError, match=rf"another run \(pid {holder.pid}\)"):
            OutputLock(out).acquire()
    finally:
        holder.kill()
        holder.wait()
    with OutputLock(out):                          # a killed holder's lock is free
        with pytest.raises(OutputBusyError):
            OutputLock(out).acquire()
    assert os.listdir(tmp_path) == []


def test_the_argparse_types_end_a_command_at_parse_time(tmp_path, capsys):
    import argparse

    from homing_gym.outputs import output_dir_argument, output_file_argument

    (tmp_path / "f.txt").write_text("x")
    parser = argparse.ArgumentParser(prog="cmd")
    parser.add_argument("--out", type=output_file_argument)
    parser.add_argument("--folder", type=output_dir_argument)
    assert parser.parse_args(["--out", "r.json"]).out == "r.json"       # the text, kept
    for argv in (["--out", ""], ["--folder", str(tmp_path / "f.txt")]):
        with pytest.raises(SystemExit) as end:
            parser.parse_args(argv)
        assert end.value.code == 2
        last = capsys.readouterr().err.strip().splitlines()[-1]
        assert last.startswith("cmd: error: argument") and ("empty" in last or "file" in last)


def test_a_figure_is_saved_in_its_extensions_format_or_not_at_all(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    save_figure(fig, tmp_path / "a.png", dpi=20)
    save_figure(fig, str(tmp_path / "a.svg"))
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in (tmp_path / "a.svg").read_bytes()[:500]
    old = (tmp_path / "a.png").read_bytes()

    def torn_save(path, **kwargs):                 # half a file, then a full disk
        open(path, "wb").write(b"\x89PNG")
        raise OSError(28, "No space left on device")
    fig.savefig = torn_save
    with pytest.raises(OSError):
        save_figure(fig, tmp_path / "a.png")
    plt.close(fig)
    assert (tmp_path / "a.png").read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "a.svg"]
