"""Is a package up to date, and if not, why: fingerprints computed in dependency order.

A build computes each package's fingerprint when its task is dispatched, after its dependencies
have been built, so it sees what they installed; ``roc work build --explain`` and the cache keys
compute them all at once, in the same order.

A fingerprint counts a dependency by its fingerprint, so it follows the sources (the CI cache keys
are computed before anything is built), but a package whose only change is a dependency rebuilt
without a change to the interface it installs (roc.builder.interface: an edit inside a library's
implementation) is up to date: its build would make the same files. It is recorded with its new
fingerprint without being built.
"""

from __future__ import annotations

from collections import namedtuple
from pathlib import Path

from roc.builder.environment import base_environment
from roc.builder.fingerprint import (
    build_tools,
    changes,
    combine,
    differing_keys,
    external_stamp,
    short_names,
    source_parts,
    source_stamps,
    toolchain_parts,
    underlay_prefixes,
)
from roc.builder.layout import package_prefix
from roc.builder.state import install_intact, read_state
from roc.buildtypes.context import BuildOptions
from roc.idl.task import generated_stamps
from roc.workspace.load import Workspace
from roc.workspace.package import Package


class PackageState(namedtuple("PackageState", ("fingerprint", "parts", "files", "stored", "interfaces"))):
    """One package now (fingerprint, its parts, the file stamps to store, its dependencies' interfaces)
    and at its last build."""

    __slots__ = ()
    fingerprint: str
    parts: dict
    files: dict
    stored: dict  # roc_state.json as read: {} when never built
    interfaces: dict  # of each dependency as installed now; None: not yet built as it is now

    def cut_off(self) -> bool:
        """Up to date although its fingerprint changed: only dependencies changed, and not their
        interfaces (stale_reasons said so); record it with its new fingerprint."""
        return bool(self.stored) and self.stored.get("fingerprint") != self.fingerprint


def _options_parts(package: Package, options: BuildOptions) -> dict:
    """The options that shape this package's build (no absolute paths: a restored cache may live in
    another directory)."""
    cmake_based = package.build_type in ("cmake", "ament_cmake")
    return {
        "type": package.type,
        "merge-install": options.merge_install,
        "symlink-install": options.symlink_install,
        "cmake-args": list(options.cmake_args_for(package.name)) if cmake_based else [],
        "ament-cmake-args": list(options.ament_cmake_args_for(package.name))
        if package.build_type == "ament_cmake" else [],
    }


class Fingerprints:
    """Fingerprints of the workspace's packages. A package that is not computed (not selected) counts
    with the fingerprint of its last successful build (what is installed), if any."""

    def __init__(self, workspace: Workspace, options: BuildOptions):
        self.workspace, self.options = workspace, options
        self.environment = base_environment()
        self.prefixes = underlay_prefixes(self.environment, options.install_base)
        self._external: dict[str, str | None] = {}
        self._now: dict[str, str] = {}
        self._interfaces: dict[str, str | None] = {}
        self._sources: dict[str, Path] = {}
        self._toolchains: dict[tuple[str, ...], dict[str, object]] = {}  # by the build type's tools

    def source(self, package: Package) -> Path:
        """The package's source directory, symbolic links resolved (once: a no-op build asks for
        every package's)."""
        if package.name not in self._sources:
            self._sources[package.name] = (self.workspace.root / package.path).resolve()
        return self._sources[package.name]

    def _toolchain(self, tools: tuple[str, ...]) -> dict[str, object]:
        if tools not in self._toolchains:
            self._toolchains[tools] = toolchain_parts(self.environment, self.options.install_base, tools)
        return self._toolchains[tools]

    def _fingerprint(self, name: str) -> str | None:
        if name in self._now:
            return self._now[name]
        return read_state(self.options.build_base / name).get("fingerprint")

    def _interface(self, name: str) -> str | None:
        """What a dependency installed for its dependents (roc.builder.interface), as built now: None
        while it waits to be built in this run."""
        if name not in self._interfaces:  # not selected: as installed
            self._interfaces[name] = read_state(self.options.build_base / name).get("interface")
        return self._interfaces[name]

    def installed(self, name: str, interface: str | None) -> None:
        """Package ``name`` is installed as it is now (built, restored or cut off), with ``interface``."""
        self._interfaces[name] = interface

    def _underlay(self, name: str) -> str | None:
        if name not in self._external:
            self._external[name] = external_stamp(name, self.prefixes)
        return self._external[name]

    def compute(self, package: Package) -> PackageState:
        """The package's state now; its dependencies must have been computed (or built) first."""
        by_name = self.workspace.by_name
        stored = read_state(self.options.build_base / package.name)
        source = self.source(package)
        files = source_stamps(source, stored.get("files", {}))
        tools = build_tools(package.build_type, self.environment, self.options.cmake_args_for(package.name))
        parts = {
            "sources": source_parts(files),
            "options": _options_parts(package, self.options),
            "toolchain": self._toolchain(tools),
            "dependencies": {n: self._fingerprint(n)
                             for n in sorted(self.workspace.dependencies.recursive(package.name))},
            "underlay": {n: self._underlay(n) for n in sorted(package.direct_dependencies() - by_name.keys())},
        }
        generated = generated_stamps(source, self.options.build_base / package.name)
        if generated is not None:  # written by the package's idl task, outside its source tree
            parts["generated"] = source_parts(generated)
        fingerprint = combine(parts)
        self._now[package.name] = fingerprint
        self._interfaces[package.name] = stored.get("interface") if stored.get("fingerprint") == fingerprint else None
        interfaces = {n: self._interface(n) for n in parts["dependencies"]}
        return PackageState(fingerprint, parts, files, stored, interfaces)


def forced_reasons(options: BuildOptions) -> list[str]:
    """The options that build every selected package whatever its state."""
    flags = [("--no-cache", not options.use_state), ("--force", options.force),
             ("--cmake-target (a partial build is never recorded as up to date)", options.partial()),
             ("--cmake-clean-cache", options.cmake_clean_cache), ("--cmake-clean-first", options.cmake_clean_first),
             ("--cmake-force-configure", options.cmake_force_configure)]
    return [flag for flag, given in flags if given]


def stale_reasons(package: Package, state: PackageState, options: BuildOptions) -> list[str]:
    """Why the package must be built (empty: it is up to date)."""
    forced = forced_reasons(options)
    if forced:
        return forced
    stored = state.stored
    if not stored:
        return ["never built"]
    if stored.get("fingerprint") is None:
        return ["its last build did not succeed"]
    if stored["fingerprint"] != state.fingerprint:
        before = stored.get("parts") or {}
        if differing_keys(before, state.parts) != ["dependencies"]:
            return changes(before, state.parts) or ["built by another version of roc"]
        reasons = _dependency_reasons(before["dependencies"], stored.get("interfaces", {}), state)
        if reasons:
            return reasons
    build_dir = options.build_base / package.name
    if not install_intact(package_prefix(options.install_base, package.name, options.merge_install),
                          package.name, build_dir):
        return ["its install is incomplete (files of its last install are missing)"]
    return []


def _dependency_reasons(before: dict, built_against: dict, state: PackageState) -> list[str]:
    """Why a package whose only changes are its dependencies' must be built: the dependencies whose
    interface changed, or that are still to be built (empty: none, it is up to date)."""
    changed, waiting = [], []
    for name in differing_keys(before, state.parts["dependencies"]):
        interface, recorded = state.interfaces.get(name), built_against.get(name)
        if interface is None and recorded is not None:
            waiting.append(name)
        elif interface is None or interface != recorded:
            changed.append(name)
    reasons = [f"dependency changed: {short_names(changed)}"] if changed else []
    if waiting:
        reasons.append(f"dependency to be built first: {short_names(waiting)} (then this package only if its "
                       "interface changes)")
    return reasons


def generation_forced(options: BuildOptions) -> list[str]:
    """The options that also make an ``idl`` task generate again whatever its state."""
    return [flag for flag in forced_reasons(options) if flag in ("--no-cache", "--force")]


def explain(workspace: Workspace, options: BuildOptions, remote=None) -> list[tuple[str, str, list[str]]]:
    """Each task of the build, in build order, as (kind, package, why it would run; empty: up to date):
    a package's ``idl`` task (protobuf sources) before its ``build`` task. With a ``remote`` cache
    (roc.remote_cache.cache.RemoteCache), a package that would be built also says whether the cache
    has it."""
    from roc.idl.task import proto_directory
    from roc.idl.task import stale_reasons as generation_reasons

    fingerprints = Fingerprints(workspace, options)
    remote_keys = None
    if remote is not None:
        from roc.remote_cache.keys import RemoteKeys

        remote_keys = RemoteKeys(fingerprints.environment, fingerprints.prefixes, options.build_base)
    explained = []
    for package in workspace.selected_in_order():
        source = (workspace.root / package.path).resolve()
        if proto_directory(source) is not None:
            explained.append(("idl", package.name, generation_reasons(source, options.build_base / package.name,
                                                                      generation_forced(options))))
        state = fingerprints.compute(package)
        reasons = stale_reasons(package, state, options)
        if remote_keys is not None:
            key = remote_keys.key(package.name, state.parts)
            if reasons and not forced_reasons(options):
                reasons.append(remote.has(key) if key else
                               f"no remote cache key (dependency '{remote_keys.missing_dependency(state.parts)}' "
                               "has none)")
        explained.append(("build", package.name, reasons))
    return explained


def anything_to_build(workspace: Workspace, options: BuildOptions) -> bool:
    """Whether a build would build (or restore) any selected package (without building anything)."""
    if forced_reasons(options):
        return bool(workspace.selected)
    fingerprints = Fingerprints(workspace, options)
    return any(stale_reasons(p, fingerprints.compute(p), options) for p in workspace.selected_in_order())


def anything_the_cache_lacks(workspace: Workspace, options: BuildOptions, remote) -> bool:
    """Whether a build would build a selected package rather than restore it from the ``remote`` cache
    (asked in build order, up to the first miss; a cache that is down lacks everything)."""
    from roc.remote_cache.keys import RemoteKeys
    from roc.remote_cache.store import StoreUnavailable

    if forced_reasons(options):
        return bool(workspace.selected)
    fingerprints = Fingerprints(workspace, options)
    remote_keys = RemoteKeys(fingerprints.environment, fingerprints.prefixes, options.build_base)
    for package in workspace.selected_in_order():
        state = fingerprints.compute(package)
        key = remote_keys.key(package.name, state.parts)  # for every package: its dependents' keys need it
        if stale_reasons(package, state, options):
            try:
                if not (key and remote.holds(key)):
                    return True
            except StoreUnavailable:
                return True
    return False


def fingerprint_packages(workspace: Workspace, options: BuildOptions) -> dict[str, PackageState]:
    """The state of every selected package now, by name."""
    fingerprints = Fingerprints(workspace, options)
    return {p.name: fingerprints.compute(p) for p in workspace.selected_in_order()}
