"""Move built packages between workspaces (CI caches): ``roc work cache export/import``.

The cache is a directory: ``index.json`` names, for each up-to-date package, its fingerprint and an
archive ``objects/<fingerprint>.tar.gz`` (content-addressed) holding the package's install prefix and
its build state. Importing checks each archive's SHA-256 (corrupt or partial entries are ignored with
a warning) and that the package does not depend on the absolute path it was built at: roc's own
scripts are regenerated, a few text files with a well-known meaning get the new path, and a package
with the old path in any other file (for example baked into a library) is left out, so the next build
rebuilds it. Only the isolated install layout is supported.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import tarfile
import tempfile
from pathlib import Path

from roc import __version__
from roc.builder.finish import finish_package
from roc.builder.state import STATE_FILE, install_intact, read_state
from roc.errors import RocError, UsageError
from roc.fsutil import file_sha256, write_text_atomic
from roc.messages import warn
from roc.workspace.package import Package

INDEX = "index.json"
# Build-state files that travel with a package (the CMake build tree itself does not).
STATE_FILES = (STATE_FILE, "colcon_build.rc", "cmake_args.last", "install_manifest.txt", "install.log")
# Files in which an old path is rewritten instead of ruling the package out: their meaning is known.
REWRITABLE = ("install_manifest.txt", "install.log", "SOURCES.txt", "local_setup.sh", "local_setup.bash",
              "local_setup.zsh")
REWRITABLE_DIRS = ("parent_prefix_path",)
# roc's own generated scripts: written again for the new place.
REGENERATED = ("package.sh", "package.bash", "package.zsh")


def _links_outside(prefix: Path) -> bool:
    """A --symlink-install prefix points into its sources: not something to restore elsewhere."""
    return any(path.is_symlink() and os.path.isabs(os.readlink(path)) for path in prefix.rglob("*"))


def export_cache(destination: Path, root: Path, build_base: Path, install_base: Path,
                 packages: list[Package], fingerprints: dict[str, str | None]) -> tuple[list[str], dict[str, str]]:
    """Store every given package whose last successful build matches its fingerprint now
    (``fingerprints``); returns the names stored, and for each other given package why it was not
    (never stored: packages that import could not restore, or that the next build would rebuild)."""
    objects = destination / "objects"
    objects.mkdir(parents=True, exist_ok=True)
    entries = {}
    left_out: dict[str, str] = {}
    for package in packages:
        build_dir, prefix = build_base / package.name, install_base / package.name
        fingerprint = read_state(build_dir).get("fingerprint")
        reason = _not_exportable(package.name, fingerprint, fingerprints.get(package.name), prefix, build_dir)
        if reason:
            left_out[package.name] = reason
            continue
        archive = objects / f"{fingerprint}.tar.gz"
        if not archive.exists():
            temporary = archive.with_name(f".{archive.name}.tmp")
            with tarfile.open(temporary, "w:gz") as tar:
                tar.add(prefix, arcname=f"install/{package.name}")
                for name in STATE_FILES:
                    if (build_dir / name).exists():
                        tar.add(build_dir / name, arcname=f"build/{package.name}/{name}")
            os.replace(temporary, archive)
        entries[package.name] = {"fingerprint": fingerprint, "sha256": file_sha256(archive)}
    index = {"roc": __version__, "workspace": str(root), "install_base": str(install_base),
             "build_base": str(build_base), "packages": entries}
    write_text_atomic(destination / INDEX, json.dumps(index, indent=1, sort_keys=True))
    return sorted(entries), left_out


def _not_exportable(name: str, stored: str | None, now: str | None, prefix: Path, build_dir: Path) -> str | None:
    """Why a package is not exported (None: it is)."""
    if not stored:
        return "not built successfully yet"
    if now != stored:
        return "not up to date (it changed since its last build; build it first)"
    if not install_intact(prefix, name, build_dir):
        return "its install prefix is incomplete (build it again)"
    if _links_outside(prefix):
        return "installed with --symlink-install: its files point into the sources"
    return None


def path_dependent_file(tree: Path, paths: list[Path]) -> str | None:
    """The first file below ``tree`` that holds one of ``paths`` where import cannot rewrite it (such a
    package can only be restored into a workspace at the same place)."""
    pattern = re.compile(b"|".join(re.escape(str(p).encode()) for p in paths))
    for path in sorted(p for p in tree.rglob("*") if p.is_file() and not p.is_symlink() and p.suffix != ".pyc"):
        data = path.read_bytes()
        if pattern.search(data) and _keeps_path(path, data):
            return str(path.relative_to(tree))
    return None


def _keeps_path(path: Path, data: bytes) -> bool:
    """Whether an old path in this file stays after import (it is neither regenerated nor rewritten)."""
    if path.name in REGENERATED or (path.parent.name == "hook" and path.suffix == ".sh"):
        return False  # written again by finish_package
    return not (_is_text(data) and (path.name in REWRITABLE or path.parent.name in REWRITABLE_DIRS))


def _is_text(data: bytes) -> bool:
    return b"\0" not in data[:8192]


def _relocate(tree: Path, replacements: dict[bytes, bytes]) -> str | None:
    """Rewrite the old paths in known text files of ``tree``; the first other file that still holds
    an old path (None when there is none)."""
    # One pass, longest old path first, so that a new path containing an old one is not rewritten again.
    pattern = re.compile(b"|".join(re.escape(old) for old in sorted(replacements, key=len, reverse=True)))
    for path in sorted(p for p in tree.rglob("*") if p.is_file() and not p.is_symlink()):
        if path.suffix == ".pyc":
            path.unlink()  # byte-code caches name their sources; Python writes them again
            continue
        data = path.read_bytes()
        if not pattern.search(data):
            continue
        if _keeps_path(path, data):
            return str(path.relative_to(tree))
        if path.name not in REGENERATED and not (path.parent.name == "hook" and path.suffix == ".sh"):
            path.write_bytes(pattern.sub(lambda match: replacements[match.group(0)], data))
    return None


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


def import_cache(source: Path, root: Path, build_base: Path, install_base: Path,
                 packages: dict[str, Package]) -> tuple[list[str], dict[str, str]]:
    """Restore the cached packages that exist in this workspace; returns (restored, left out: why)."""
    index = _read_index(source)
    entries = index["packages"]
    replacements = {index[key].encode(): str(new).encode() for key, new in
                    (("install_base", install_base), ("build_base", build_base), ("workspace", root))}
    restored: list[str] = []
    left_out: dict[str, str] = {}
    for name, entry in sorted(entries.items()):
        if name not in packages:
            continue
        archive = source / "objects" / f"{entry['fingerprint']}.tar.gz"
        if not archive.is_file() or file_sha256(archive) != entry["sha256"]:
            left_out[name] = "its cache entry is missing or damaged"
            warn(f"{archive}: missing or damaged cache entry; '{name}' will be rebuilt")
            continue
        reason = _restore(archive, name, packages[name], replacements, build_base, install_base)
        if reason:
            left_out[name] = reason
        else:
            restored.append(name)
    return restored, left_out


def _restore(archive: Path, name: str, package: Package, replacements, build_base: Path,
             install_base: Path) -> str | None:
    with tempfile.TemporaryDirectory(dir=install_base.parent, prefix=".roc-import-") as temporary:
        tree = Path(temporary)
        try:
            with tarfile.open(archive) as tar:
                tar.extractall(tree, filter="data")
        except (tarfile.TarError, OSError, EOFError) as error:
            warn(f"{archive}: unreadable cache entry ({error}); '{name}' will be rebuilt")
            return "its cache entry is unreadable"
        moved = any(old != new for old, new in replacements.items())
        depends_on_path = _relocate(tree, replacements) if moved else None
        if depends_on_path:
            return f"{depends_on_path} holds the absolute path it was built at"
        prefix, build_dir = install_base / name, build_base / name
        if prefix.exists():
            shutil.rmtree(prefix)
        os.replace(tree / "install" / name, prefix)
        build_dir.mkdir(parents=True, exist_ok=True)
        for item in (tree / "build" / name).iterdir():
            os.replace(item, build_dir / item.name)
    finish_package(package, prefix)  # roc's scripts, written for the new place
    return None


def check_isolated(merge_install: bool) -> None:
    if merge_install:
        raise UsageError("roc work cache supports the isolated install layout only (no --merge-install)")
