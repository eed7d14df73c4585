"""File helpers: every file roc writes is written whole or not at all."""

from __future__ import annotations

import os
from pathlib import Path


def _umask() -> int:
    """The process umask (read once at import: os.umask can only be read by setting it)."""
    current = os.umask(0o022)
    os.umask(current)
    return current


UMASK = _umask()


def write_text_atomic(path: Path, text: str, mode: int | None = None) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename (never half-written), with the
    permissions a plain write would give (mkstemp makes private files)."""
    _write_atomic(path, text, "w", mode)


def write_bytes_atomic(path: Path, data: bytes) -> None:
    """``write_text_atomic`` for bytes."""
    _write_atomic(path, data, "wb", None)


def _write_atomic(path: Path, data: str | bytes, open_mode: str, mode: int | None) -> None:
    import tempfile  # not at module level: start-up stays light for read-only commands

    path.parent.mkdir(parents=True, exist_ok=True)
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, open_mode) as handle:
            handle.write(data)
        os.chmod(temporary, mode if mode is not None else 0o666 & ~UMASK)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def write_text_if_changed(path: Path, text: str) -> bool:
    """``write_text_atomic``, skipped when the file already holds ``text`` (a no-op build then renames
    nothing: a rename costs about a millisecond here); whether it wrote."""
    try:
        if path.read_text() == text:
            return False
    except (OSError, UnicodeDecodeError):
        pass
    write_text_atomic(path, text)
    return True


def file_sha256(path: Path) -> str:
    import hashlib

    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def read_yaml(path: Path, nodes: bool = False):
    """A YAML file's document (``nodes``: its node tree, which keeps a mapping's repeated keys); a
    one-line UsageError naming the file (and line) when it cannot be read or parsed."""
    import yaml

    from roc.errors import UsageError

    try:
        text = path.read_text()
        return yaml.compose(text, Loader=yaml.SafeLoader) if nodes else yaml.safe_load(text)
    except OSError as error:
        raise UsageError(f"{path}: cannot read it ({error.strerror})") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f":{mark.line + 1}" if mark else ""
        raise UsageError(f"{path}{where}: not valid YAML ({getattr(error, 'problem', None) or error})") from None
