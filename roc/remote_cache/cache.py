"""Restore packages from the remote cache and upload what was built, inside the packages' build tasks.

The store holds two kinds of blob:

- ``ac/<key>``: a small JSON entry for a package's remote key (roc.remote_cache.keys): the SHA-256 and
  size of its archive, where it was built, and whether it can be restored elsewhere;
- ``cas/<sha256>``: the archive (roc.builder.artefact), named by its own SHA-256.

An upload puts the archive first, the entry last, so an entry never names an archive that was not
there; two jobs uploading the same key leave one whole entry (the last), each naming a whole archive.
A lookup reads the entry at the key, else at the key placed at this workspace's paths (a package
whose files hold its build path), fetches the archive into the build directory, checks its size and
SHA-256, and only then unpacks it. Anything damaged is a miss with a warning, never a broken install.
The first time the server cannot be used (down, too slow, refusing access) gives one warning, and the
rest of the run builds locally without asking it again.
"""

from __future__ import annotations

import json
import os
import re
import threading
from pathlib import Path

from roc import __version__
from roc.builder.artefact import (
    Places,
    installed_files,
    not_packable,
    pack,
    path_dependent_file,
    unpack,
)
from roc.engine.events import TaskWarning
from roc.engine.process import TaskContext
from roc.fsutil import file_sha256, write_text_atomic
from roc.remote_cache.keys import FORMAT, placed_key
from roc.remote_cache.settings import RemoteSettings
from roc.remote_cache.store import Store, StoreUnavailable
from roc.workspace.package import Package

_SHA256 = re.compile(r"[0-9a-f]{64}")


def open_store(settings: RemoteSettings) -> Store:
    """The store for the settings' URL (its client library imported only now)."""
    if settings.url.startswith("s3://"):
        from roc.remote_cache.s3_store import S3Store

        return S3Store(settings.url, settings.timeout)
    from roc.remote_cache.http_store import HttpStore

    return HttpStore(settings.url, settings.timeout)


class RemoteCache:
    """One run's use of the remote cache (shared by the worker threads)."""

    def __init__(self, settings: RemoteSettings, places: Places, merged: bool, store: Store | None = None):
        self.settings, self.places, self.merged = settings, places, merged
        self._store = store
        self._lock = threading.Lock()
        self.unavailable: str | None = None  # why the server is no longer asked, once it failed

    def store(self) -> Store:
        with self._lock:
            if self._store is None:
                self._store = open_store(self.settings)
            return self._store

    def _gave_up(self, context: TaskContext | None, error: StoreUnavailable) -> str:
        """Note a server failure; the first one warns (through the task's events)."""
        with self._lock:
            first = self.unavailable is None
            if first:
                self.unavailable = str(error)
        if first and context is not None:
            context.emit(TaskWarning(context.name, context.kind, message=(
                f"remote cache {self.settings.shown}: {error}; building locally without it for the rest "
                f"of this run")))
        return f"remote cache unavailable ({self.unavailable})"

    # ------------------------------------------------------------------------------------- restore

    def restore(self, package: Package, key: str, context: TaskContext) -> str | None:
        """Fetch, check and unpack the package's entry; None when restored, else why not."""
        if self.unavailable:
            return f"remote cache unavailable ({self.unavailable})"
        build_dir = self.places.build_base / package.name
        build_dir.mkdir(parents=True, exist_ok=True)
        entry_path = build_dir / ".roc-remote-entry.json"
        archive = build_dir / ".roc-remote-archive.tar.gz"
        try:
            found = self._fetch(key, entry_path, archive, context)
            if isinstance(found, str):
                return found
            reason = unpack(archive, package, found, self.places, self.merged)
            if reason:
                self._warn(context, f"remote cache entry {key[:12]} not restored: {reason}; building it")
                return f"remote cache entry not usable: {reason}"
            return None
        except StoreUnavailable as error:
            return self._gave_up(context, error)
        finally:
            entry_path.unlink(missing_ok=True)
            archive.unlink(missing_ok=True)

    def _fetch(self, key: str, entry_path: Path, archive: Path, context: TaskContext) -> Places | str:
        """Download the entry and its archive, checked; the places it was built at, or a miss reason."""
        store = self.store()
        for lookup in (key, placed_key(key, self.places)):
            if store.get(f"ac/{lookup}", entry_path):
                break
        else:
            return f"not in the remote cache (key {key[:12]})"
        entry = _read_entry(entry_path)
        if isinstance(entry, str):
            self._warn(context, f"remote cache entry {key[:12]} is damaged ({entry}); building it")
            return f"damaged remote cache entry ({entry})"
        if not store.get(f"cas/{entry['sha256']}", archive):
            return f"the remote cache entry's archive is gone (key {key[:12]})"
        if archive.stat().st_size != entry["size"] or file_sha256(archive) != entry["sha256"]:
            self._warn(context, f"remote cache archive {entry['sha256'][:12]} is partial or corrupt "
                                f"(SHA-256 or size differs); building it")
            return "partial or corrupt remote cache archive"
        return Places.from_dict(entry["built_at"])

    @staticmethod
    def _warn(context: TaskContext, message: str) -> None:
        context.emit(TaskWarning(context.name, context.kind, message=message))

    # -------------------------------------------------------------------------------------- upload

    def upload(self, package: Package, key: str, context: TaskContext) -> None:
        """Store a package just built (read-write mode). Packages whose install cannot travel
        (--symlink-install) are left out; a failure warns and never fails the build."""
        if self.unavailable or not_packable(package.name, self.places, self.merged):
            return
        build_dir = self.places.build_base / package.name
        archive = build_dir / ".roc-upload.tar.gz"
        entry_path = build_dir / ".roc-upload.json"
        try:
            pack(archive, package.name, self.places, self.merged)
            files = installed_files(package.name, self.places, self.merged)
            bound = path_dependent_file(files, self.places.install_base, self.places)
            sha256 = file_sha256(archive)
            entry = {"format": FORMAT, "roc": __version__, "package": package.name, "key": key,
                     "sha256": sha256, "size": archive.stat().st_size, "built_at": self.places.as_dict(),
                     "layout": "merged" if self.merged else "isolated", "path_dependent": bound}
            write_text_atomic(entry_path, json.dumps(entry, indent=1, sort_keys=True))
            store = self.store()
            if not store.exists(f"cas/{sha256}"):
                store.put(f"cas/{sha256}", archive)
            store.put(f"ac/{placed_key(key, self.places) if bound else key}", entry_path)
        except StoreUnavailable as error:
            self._gave_up(context, error)
        except OSError as error:
            self._warn(context, f"could not pack it for the remote cache: {error}")
        finally:
            archive.unlink(missing_ok=True)
            entry_path.unlink(missing_ok=True)

    # ------------------------------------------------------------------------------------- explain

    def has(self, key: str) -> str:
        """For --explain: whether a build would restore the key (without fetching anything)."""
        if self.unavailable:
            return f"remote cache unavailable ({self.unavailable})"
        try:
            if self.holds(key):
                return f"in the remote cache (key {key[:12]}): it would be restored"
            return f"not in the remote cache (key {key[:12]})"
        except StoreUnavailable as error:
            self.unavailable = str(error)
            return f"remote cache unavailable ({error})"

    def holds(self, key: str) -> bool:
        """Whether the store has an entry a restore of the key would take (StoreUnavailable when it is down)."""
        store = self.store()
        return store.exists(f"ac/{key}") or store.exists(f"ac/{placed_key(key, self.places)}")


def _read_entry(path: Path) -> dict | str:
    """An ``ac/`` entry, checked for the shape upload writes; a string says what is wrong."""
    try:
        entry = json.loads(path.read_text())
    except (OSError, ValueError):
        return "not JSON: a partial upload?"
    if not isinstance(entry, dict) or entry.get("format") != FORMAT:
        return "of another format"
    built_at = entry.get("built_at")
    if not (isinstance(entry.get("sha256"), str) and _SHA256.fullmatch(entry["sha256"])
            and isinstance(entry.get("size"), int) and isinstance(built_at, dict)
            and all(isinstance(built_at.get(k), str) and os.path.isabs(built_at[k])
                    for k in ("workspace", "build_base", "install_base"))):
        return "malformed"
    return entry
