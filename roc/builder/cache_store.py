"""Move built packages between workspaces (CI caches): ``roc work cache export/import``.

The cache is a directory: ``index.json`` names, for each up-to-date package, its fingerprint and an
archive ``objects/<fingerprint>.tar.gz`` (content-addressed; packed and unpacked by
roc.builder.artefact) holding the package's install prefix and its build state. Importing checks
each archive's SHA-256 (corrupt or partial entries are ignored with a warning) and that the package
does not depend on the absolute path it was built at: roc's own scripts are regenerated, a few text
files with a well-known meaning get the new path, and a package with the old path in any other file
(for example baked into a library) is left out, so the next build rebuilds it. Only the isolated
install layout is supported.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from roc import __version__
from roc.builder.artefact import Places, not_packable, pack, unpack
from roc.builder.state import read_state
from roc.errors import RocError, UsageError
from roc.fsutil import file_sha256, write_text_atomic
from roc.messages import warn
from roc.workspace.package import Package

INDEX = "index.json"


def export_cache(destination: Path, places: Places, packages: list[Package],
                 fingerprints: dict[str, str | None]) -> tuple[list[str], dict[str, str]]:
    """Store every given package whose last successful build matches its fingerprint now
    (``fingerprints``); returns the names stored, and for each other given package why it was not
    (never stored: packages that import could not restore, or that the next build would rebuild)."""
    objects = destination / "objects"
    objects.mkdir(parents=True, exist_ok=True)
    entries = {}
    left_out: dict[str, str] = {}
    for package in packages:
        fingerprint = read_state(places.build_base / package.name).get("fingerprint")
        reason = _not_exportable(package.name, fingerprint, fingerprints.get(package.name), places)
        if reason:
            left_out[package.name] = reason
            continue
        archive = objects / f"{fingerprint}.tar.gz"
        if not archive.exists():
            pack(archive, package.name, places, merged=False)
        entries[package.name] = {"fingerprint": fingerprint, "sha256": file_sha256(archive)}
    index = {"roc": __version__, **places.as_dict(), "packages": entries}
    write_text_atomic(destination / INDEX, json.dumps(index, indent=1, sort_keys=True))
    return sorted(entries), left_out


def _not_exportable(name: str, stored: str | None, now: str | None, places: Places) -> str | None:
    """Why a package is not exported (None: it is)."""
    if not stored:
        return "not built successfully yet"
    if now != stored:
        return "not up to date (it changed since its last build; build it first)"
    return not_packable(name, places, merged=False)


def _read_index(source: Path) -> dict:
    """The cache's index, checked for the shape export writes (anything else is not trusted)."""
    problem = None
    try:
        index = json.loads((source / INDEX).read_text())
    except (OSError, ValueError) as error:
        problem = str(error)
    else:
        strings = ("workspace", "install_base", "build_base")
        if not isinstance(index, dict) or not all(isinstance(index.get(k), str) for k in strings):
            problem = "its index.json lacks the workspace, install_base or build_base paths"
        elif not isinstance(index.get("packages"), dict) or not all(
                isinstance(entry, dict) and isinstance(entry.get("fingerprint"), str)
                and re.fullmatch(r"[0-9a-f]{64}", entry["fingerprint"]) and isinstance(entry.get("sha256"), str)
                for entry in index["packages"].values()):
            problem = "its index.json has malformed package entries"
    if problem:
        raise RocError(f"{source}: not a usable roc cache ({problem}); make one with 'roc work cache export'")
    return index


def import_cache(source: Path, places: Places, packages: dict[str, Package]) -> tuple[list[str], dict[str, str]]:
    """Restore the cached packages that exist in this workspace; returns (restored, left out: why)."""
    index = _read_index(source)
    built_at = Places.from_dict(index)
    restored: list[str] = []
    left_out: dict[str, str] = {}
    for name, entry in sorted(index["packages"].items()):
        if name not in packages:
            continue
        archive = source / "objects" / f"{entry['fingerprint']}.tar.gz"
        if not archive.is_file() or file_sha256(archive) != entry["sha256"]:
            left_out[name] = "its cache entry is missing or damaged"
            warn(f"{archive}: missing or damaged cache entry; '{name}' will be rebuilt")
            continue
        reason = unpack(archive, packages[name], built_at, places, merged=False)
        if reason and reason.startswith("its archive is unreadable"):
            warn(f"{archive}: unreadable cache entry; '{name}' will be rebuilt")
        if reason:
            left_out[name] = reason
        else:
            restored.append(name)
    return restored, left_out


def check_isolated(merge_install: bool) -> None:
    if merge_install:
        raise UsageError("roc work cache supports the isolated install layout only (no --merge-install)")
