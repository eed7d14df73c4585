"""Files that travel with a cluster task as one gzip'd tar: a package's sources to the worker, its test
results back (through the remote cache). Unpacking refuses absolute names, ``..`` and links that leave
the folder (tarfile's ``data`` filter)."""

from __future__ import annotations

import io
import shutil
import tarfile
from collections.abc import Iterable
from pathlib import Path

# What a package's test run leaves in its result folder (CTest's Testing/, ament's test_results/, pytest's file)
RESULT_FILES = ("Testing", "test_results", "pytest.xml")


def pack_files(base: Path, relative: Iterable[str]) -> bytes:
    """The files at ``relative`` paths below ``base`` (links followed, as the fingerprints follow
    them; modes kept), sorted."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz", dereference=True) as tar:
        for name in sorted(relative):
            path = base / name
            if path.is_file():
                tar.add(path, arcname=name, recursive=False)
    return buffer.getvalue()


def unpack_files(data: bytes, destination: Path) -> list[str]:
    """Unpack what ``pack_files`` made into ``destination``; the relative paths written."""
    destination.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        names = [member.name for member in tar.getmembers() if member.isfile()]
        tar.extractall(destination, filter="data")
    return names


def remove_path(path: Path) -> None:
    """Remove a file, a link or a folder tree (a link itself, never what it points to)."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)
