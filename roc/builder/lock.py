"""One build per build base at a time: a second ``roc work build`` waits for the first, saying so."""

from __future__ import annotations

import fcntl
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

LOCK_FILE = ".roc_lock"


@contextmanager
def build_lock(build_base: Path) -> Iterator[None]:
    build_base.mkdir(parents=True, exist_ok=True)
    handle = open(build_base / LOCK_FILE, "a+")
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            owner = handle.read().strip() or "another process"
            print(f"roc: {build_base} is being built by {owner}; waiting for it to finish (Ctrl+C to stop)",
                  file=sys.stderr, flush=True)
            fcntl.flock(handle, fcntl.LOCK_EX)
        handle.seek(0)
        handle.truncate()
        handle.write(f"roc (pid {os.getpid()})")
        handle.flush()
        yield
    finally:
        handle.close()  # closing releases the lock
