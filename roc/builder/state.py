"""Per-package build state in ``<build-base>/<pkg>/roc_state.json``: the fingerprint of the last
successful build and its parts (to say what changed since), the file stamps that make the next
check cheap, and the interfaces of what it installed and of what it was built against
(roc.builder.uptodate).
Written atomically; a damaged file is reported and ignored (the package is rebuilt), never trusted."""

from __future__ import annotations

import json
import os
from pathlib import Path

from roc.fsutil import write_text_atomic
from roc.messages import warn

STATE_FILE = "roc_state.json"


def read_record(path: Path, damaged: str, fields: tuple[str, ...] = ("files",)) -> dict:
    """A JSON state record: {} when there is none; {} and the warning ``<path>: <damaged>`` when it is
    not an object whose ``fields`` (where present) are objects."""
    try:
        state = json.loads(path.read_text())
    except FileNotFoundError:
        return {}
    except (OSError, ValueError):
        state = None
    if isinstance(state, dict) and all(isinstance(state.get(field, {}), dict) for field in fields):
        return state
    warn(f"{path}: {damaged}")
    return {}


def read_state(build_dir: Path) -> dict:
    return read_record(build_dir / STATE_FILE, "damaged build state; the package will be rebuilt",
                       ("files", "interfaces"))


def write_state(build_dir: Path, fingerprint: str | None, files: dict, parts: dict | None = None,
                remote_key: str | None = None, interface: str | None = None,
                interfaces: dict[str, str | None] | None = None) -> None:
    """Record ``fingerprint`` (made of ``parts``) as built; None: not up to date (a build started).
    ``remote_key``: the package's remote cache key (roc.remote_cache.keys), when it has one;
    ``interface``: what it installed for its dependents (roc.builder.interface); ``interfaces``: its
    dependencies' interfaces it was built against."""
    state = {"fingerprint": fingerprint, "files": files, "parts": parts}
    if remote_key:
        state["remote_key"] = remote_key
    if interface:
        state["interface"] = interface
    if interfaces:
        state["interfaces"] = interfaces
    write_text_atomic(build_dir / STATE_FILE, json.dumps(state, separators=(",", ":")))


def install_intact(prefix: Path, name: str, build_dir: Path) -> bool:
    """The package's install markers and every file its last install recorded still exist."""
    if not (prefix / "share" / "colcon-core" / "packages" / name).is_file():
        return False
    if not (prefix / "share" / name / "package.dsv").is_file():
        return False
    for manifest in ("install_manifest.txt", "install.log"):
        try:
            lines = (build_dir / manifest).read_text().splitlines()
        except (FileNotFoundError, NotADirectoryError):
            continue
        for line in lines:  # os.path, not pathlib: this runs for every installed file on a no-op build
            if line and not line.endswith(".pyc") and not os.path.lexists(line):
                return False
    return True


SAID_FILE = "roc_said.json"  # in the build base: what was said about the workspace (not_said_yet)


def not_said_yet(build_base: Path, stamp: str, messages: list[str]) -> list[str]:
    """The ``messages`` about the workspace that were not said since ``stamp`` (of what they come from)
    last changed, and remember them as said in ``build_base``: a warning about a manifest is said
    once, not on every build (a no-op included). A file that cannot be read or written is no memory."""
    path = build_base / SAID_FILE
    try:
        record = json.loads(path.read_text())
        said = set(record["said"]) if record["stamp"] == stamp else set()
    except (OSError, ValueError, KeyError, TypeError):
        said = set()
    new = [message for message in messages if message not in said]
    if new:
        try:
            build_base.mkdir(parents=True, exist_ok=True)
            write_text_atomic(path, json.dumps({"stamp": stamp, "said": sorted(said | set(new))}))
        except OSError:
            pass
    return new
