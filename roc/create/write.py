"""Write a new package directory whole or not at all."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from roc.errors import RocError


def write_package(destination: Path, name: str, files: dict[str, str]) -> Path:
    """Write ``files`` into a temporary directory next to ``destination/name``, then rename it into
    place: an error or Ctrl+C leaves nothing behind, and an existing directory is never touched."""
    target = destination / name
    if target.exists() or target.is_symlink():
        raise RocError(f"{target} already exists; remove it or choose another name or --destination-directory")
    try:
        destination.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(dir=destination, prefix=f".{name}.roc-create-"))
    except OSError as error:
        raise RocError(f"cannot create a package in {destination}: {error.strerror}") from None
    try:
        os.chmod(staging, 0o777 & ~_umask())  # mkdtemp makes it 0700; a package directory is a normal one
        for relative, text in files.items():
            path = staging / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        if target.exists() or target.is_symlink():  # appeared meanwhile: keep it as it is
            raise RocError(f"{target} already exists; remove it or choose another name or --destination-directory")
        os.rename(staging, target)
    except BaseException as error:
        shutil.rmtree(staging, ignore_errors=True)
        if isinstance(error, OSError):
            raise RocError(f"cannot write {target}: {error.strerror or error}") from None
        raise
    return target


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
