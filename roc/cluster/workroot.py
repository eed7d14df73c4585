"""A worker's work root (``roc work worker --root DIR``): workspaces of its own (``slots/N/`` with
``src/``, ``build/`` and ``install/``) at paths no client has, one per package the worker builds at
once.

A slot is kept from task to task, as a developer's workspace is: a dependency restored there stays
(restored again only when its remote key changes), and a package built there keeps its build tree (a
rebuild is incremental; its test task finds it). Each task locks its slot. A task that dies with its
worker (SIGKILL) leaves a marker naming its package: the next task in the slot first stops the
commands still running there and removes that package's half-built build and install folders.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

from roc.fsutil import write_text_atomic

LOCK, BUSY = ".roc-lock", ".roc-busy"


class WorkRoot:
    def __init__(self, root: Path):
        self.root = root

    @contextlib.contextmanager
    def slot(self, package: str) -> Iterator[Path]:
        """A free workspace, locked, for one task on ``package``."""
        index = 0
        while True:
            folder = self.root / "slots" / str(index)
            folder.mkdir(parents=True, exist_ok=True)
            lock = _try_lock(folder)
            if lock is not None:
                break
            index += 1
        try:
            _recover(folder)
            write_text_atomic(folder / BUSY, package)
            yield folder
            (folder / BUSY).unlink(missing_ok=True)
        finally:
            os.close(lock)


def _recover(folder: Path) -> None:
    """After a task that died in ``folder``: stop what it left running, remove what it half made."""
    try:
        package = (folder / BUSY).read_text().strip()
    except OSError:
        return
    stop_processes_in(folder)
    for half_made in (folder / "build" / package, folder / "install" / package):
        shutil.rmtree(half_made, ignore_errors=True)
    (folder / BUSY).unlink(missing_ok=True)


def stop_processes_in(folder: Path) -> None:
    """Kill every process working in ``folder`` (its working directory there): the commands a killed
    worker could not stop."""
    import psutil

    inside = str(folder) + os.sep
    found = []
    for process in psutil.process_iter():
        with contextlib.suppress(psutil.Error):
            if (process.cwd() + os.sep).startswith(inside):
                found.append(process)
    for process in found:
        with contextlib.suppress(psutil.Error):
            process.kill()
    psutil.wait_procs(found, timeout=10)


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
