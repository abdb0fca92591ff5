"""Silence what native libraries print straight to the process' stdout and stderr.

PyBullet's C++ core writes ``pybullet build time: ...`` when the module is first imported
and ``argv[0]=`` on every connection, below Python's ``sys.stdout``, so a redirected table
(``homing-eval ... > out.txt``) would carry them. :func:`native_output_captured` sends file
descriptors 1 and 2 to a temporary file for the duration of a block; if the block raises,
the captured text is written to stderr before the exception propagates, so real errors
stay visible.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def native_output_captured() -> Iterator[None]:
    """Run the block with the process' stdout/stderr descriptors captured (see module)."""
    for stream in (sys.stdout, sys.stderr):
        if stream is not None:
            stream.flush()
    saved = (os.dup(1), os.dup(2))
    failed = False
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield
        except BaseException:
            failed = True
            raise
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            if failed:
                sink.seek(0)
                sys.stderr.write(sink.read().decode(errors="replace"))
