"""Turn the selected packages into engine tasks: environment, handler, install hooks."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable
from pathlib import Path

from roc.builder.fingerprint import (
    combine,
    external_stamp,
    source_digest,
    toolchain_digest,
    underlay_prefixes,
)
from roc.builder.finish import finish_package
from roc.builder.layout import package_prefix
from roc.builder.state import install_intact, read_state, write_state
from roc.buildtypes.cmake import build_cmake
from roc.buildtypes.context import BuildOptions, PackageJob
from roc.buildtypes.python import build_python
from roc.engine.jobserver import Jobserver
from roc.engine.process import TaskContext
from roc.engine.ready import Task
from roc.environment.dsv import apply_operations, resolve_operations
from roc.fsutil import write_text_atomic
from roc.workspace.dependencies import recursive_dependencies
from roc.workspace.load import Workspace
from roc.workspace.package import Package

HANDLERS: dict[str, Callable[[TaskContext, PackageJob, BuildOptions], None]] = {
    "ros.ament_cmake": build_cmake,
    "ros.cmake": build_cmake,
    "cmake": build_cmake,
    "ros.ament_python": build_python,
    "python": build_python,
}
ENVIRONMENT_FILE = "roc_build_environment.json"


def base_environment() -> dict[str, str]:
    """The calling environment. When no ROS environment is sourced but roc's own Python prefix holds
    ROS packages (ROS installed from wheels into a venv), that prefix is the underlay."""
    env = dict(os.environ)
    prefix = Path(sys.prefix)
    if not env.get("AMENT_PREFIX_PATH") and (prefix / "share" / "ament_index" / "resource_index").is_dir():
        env["AMENT_PREFIX_PATH"] = str(prefix)
    return env


def build_environment(package: Package, dependencies: list[str], options: BuildOptions) -> dict[str, str]:
    """The base environment plus the install hooks of ``dependencies`` (in dependency order)."""
    env = base_environment()
    for name in dependencies:
        prefix = package_prefix(options.install_base, name, options.merge_install)
        dsv = prefix / "share" / name / "package.dsv"
        if dsv.is_file():
            apply_operations(env, prefix, resolve_operations(prefix, dsv))
    if package.type == "ros.ament_cmake":
        # As colcon-ros does: CMake finds ament packages of every AMENT_PREFIX_PATH entry.
        cmake_paths = [p for p in env.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
        extra = [p for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p and p not in cmake_paths]
        env["CMAKE_PREFIX_PATH"] = os.pathsep.join(cmake_paths + extra)
    return env


def saved_environment(build_base: Path, name: str) -> dict[str, str] | None:
    path = build_base / name / ENVIRONMENT_FILE
    return json.loads(path.read_text()) if path.is_file() else None


def _options_digest(package: Package, options: BuildOptions) -> dict:
    """The options that shape this package's build (no absolute paths: a restored cache may live in
    another directory)."""
    cmake_based = package.build_type in ("cmake", "ament_cmake")
    return {
        "type": package.type,
        "merge": options.merge_install,
        "symlink": options.symlink_install,
        "cmake_args": list(options.cmake_args_for(package.name)) if cmake_based else [],
        "ament_cmake_args": list(options.ament_cmake_args_for(package.name)) if package.build_type == "ament_cmake"
        else [],
    }


class PackageState:
    """What planning knows of one selected package: its fingerprint now, the one of its last
    successful build, and the file stamps to store after building it."""

    def __init__(self, fingerprint: str | None, stored: str | None, files: dict):
        self.fingerprint, self.stored, self.files = fingerprint, stored, files


def fingerprint_packages(workspace: Workspace, options: BuildOptions) -> dict[str, PackageState]:
    """Fingerprints of the selected packages, in topological order. A package that is not selected
    counts with the fingerprint of its last successful build (what is installed), if known."""
    by_name = workspace.by_name
    environment = base_environment()
    toolchain = toolchain_digest(environment, options.install_base)
    prefixes = underlay_prefixes(environment, options.install_base)
    external: dict[str, str | None] = {}
    fingerprints: dict[str, str | None] = {}
    states: dict[str, PackageState] = {}
    for package in workspace.ordered:
        state = read_state(options.build_base / package.name)
        if package.name not in workspace.selected:
            fingerprints[package.name] = state.get("fingerprint")
            continue
        sources, files = source_digest((workspace.root / package.path).resolve(), state.get("files", {}))
        recursive = recursive_dependencies(package, by_name)
        for name in package.direct_dependencies() - by_name.keys():
            if name not in external:
                external[name] = external_stamp(name, prefixes)
        fingerprint = combine({
            "sources": sources, "options": _options_digest(package, options), "toolchain": toolchain,
            "dependencies": {n: fingerprints.get(n) for n in sorted(recursive)},
            "underlay": {n: external[n] for n in sorted(package.direct_dependencies() - by_name.keys())},
        })
        fingerprints[package.name] = fingerprint
        states[package.name] = PackageState(fingerprint, state.get("fingerprint"), files)
    return states


def plan_build(
    workspace: Workspace, options: BuildOptions, jobserver: Jobserver | None, weights: dict[str, float]
) -> list[Task]:
    by_name = workspace.by_name
    order = [p.name for p in workspace.ordered]
    selected = workspace.selected
    states = fingerprint_packages(workspace, options) if options.use_state else {}
    tasks = []
    for package in workspace.selected_in_order():
        recursive = recursive_dependencies(package, by_name)
        dependencies = [n for n in order if n in recursive]
        prefix = package_prefix(options.install_base, package.name, options.merge_install)
        source = (workspace.root / package.path).resolve()
        state = states.get(package.name, PackageState(None, None, {}))
        fingerprint = None if options.partial() else state.fingerprint
        up_to_date = (
            fingerprint is not None and not options.always_rebuild() and state.stored == fingerprint
            and install_intact(prefix, package.name, options.build_base / package.name)
        )
        tasks.append(Task(
            name=package.name,
            dependencies={n for n in dependencies if n in selected},
            action=_package_action(package, source, prefix, dependencies, options, jobserver, fingerprint,
                                   state.files),
            weight=weights.get(package.name, 1.0),
            up_to_date=up_to_date,
        ))
    return tasks


def _package_action(package: Package, source: Path, prefix: Path, dependencies: list[str], options: BuildOptions,
                    jobserver: Jobserver | None, fingerprint: str | None, files: dict):
    def action(context: TaskContext) -> None:
        env = build_environment(package, dependencies, options)
        job = PackageJob(package=package, source=source, build_dir=options.build_base / package.name,
                         prefix=prefix, env=env)
        if jobserver is not None:
            job.make_flags = jobserver.makeflags(env.get("MAKEFLAGS", ""))
            job.pass_fds = jobserver.fds
        job.build_dir.mkdir(parents=True, exist_ok=True)
        # Until it succeeds (and even with --no-cache, which records no new one), no old fingerprint
        # may vouch for what this build is about to install.
        write_state(job.build_dir, None, files)
        write_text_atomic(job.build_dir / ENVIRONMENT_FILE, json.dumps(env, indent=1, sort_keys=True))
        HANDLERS[package.type](context, job, options)
        finish_package(package, job.prefix)
        if options.use_state:
            write_state(job.build_dir, fingerprint, files)

    return action
