"""A worker's work root (``roc work worker --root DIR``): one folder per task attempt, below it a
workspace of its own (``src/``, ``build/``, ``install/``) at a path no client has.

Each attempt gets a new folder, locked while its task runs: a task that runs again after its worker
was killed never meets the commands the killed one left running. A folder whose build succeeded is
remembered under its remote key, so that a test task of the same package on this worker uses its
build tree (CTest needs one). Unlocked folders beyond the ``keep`` newest builds are removed when a
task starts.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path

from roc.fsutil import write_text_atomic

LOCK = ".roc-lock"


class WorkRoot:
    def __init__(self, root: Path, keep: int = 4):
        self.root, self.keep = root, keep
        self.work, self.done = root / "work", root / "done"
        self._mutex = threading.Lock()  # a folder is locked before another thread of the worker tidies

    @contextlib.contextmanager
    def attempt(self, key: str, reuse: bool = False) -> Iterator[Path]:
        """A locked folder for one task on the package with remote key ``key``: with ``reuse``, the one
        of the last successful build of that key here, when no other task holds it."""
        with self._mutex:
            self.work.mkdir(parents=True, exist_ok=True)
            self.done.mkdir(parents=True, exist_ok=True)
            self._tidy()
            folder = self._done_folder(key) if reuse else None
            lock = _try_lock(folder) if folder is not None else None
            if lock is None:
                folder = Path(tempfile.mkdtemp(prefix=f"{key[:16]}-", dir=self.work))
                lock = _try_lock(folder)
        assert folder is not None and lock is not None
        try:
            yield folder
        finally:
            os.close(lock)

    def succeeded(self, key: str, folder: Path) -> None:
        """``folder`` holds a whole build of ``key``."""
        write_text_atomic(self.done / key[:16], folder.name)

    def _done_folder(self, key: str) -> Path | None:
        try:
            folder = self.work / (self.done / key[:16]).read_text().strip()
        except OSError:
            return None
        return folder if folder.is_dir() else None

    def _tidy(self) -> None:
        kept = sorted(self.done.iterdir(), key=lambda p: p.stat().st_mtime, reverse=True)
        keep = set()
        for pointer in kept[self.keep:]:
            pointer.unlink(missing_ok=True)
        for pointer in kept[:self.keep]:
            with contextlib.suppress(OSError):
                keep.add(pointer.read_text().strip())
        for folder in self.work.iterdir():
            if folder.name in keep or not folder.is_dir():
                continue
            lock = _try_lock(folder)
            if lock is not None:  # no task uses it
                shutil.rmtree(folder, ignore_errors=True)
                os.close(lock)


def _try_lock(folder: Path) -> int | None:
    """An exclusive lock on the folder (its descriptor), or None when a running task holds it."""
    try:
        descriptor = os.open(folder / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError:
        return None
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(descriptor)
        return None
    return descriptor
