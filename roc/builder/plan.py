"""Turn the selected packages into engine tasks: environment, build type, install hooks.

Each selected package gets a ``build`` task; a package with protobuf sources also gets an ``idl`` task
(its code generation, roc.idl.task), which its build task waits for."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from roc.builder.environment import ENVIRONMENT_FILE, build_environment
from roc.builder.estimate import package_weight
from roc.builder.finish import finish_package
from roc.builder.interface import install_interface
from roc.builder.layout import package_prefix
from roc.builder.state import write_state
from roc.builder.uptodate import (
    Fingerprints,
    PackageState,
    forced_reasons,
    generation_forced,
    stale_reasons,
)
from roc.buildtypes import build_function
from roc.buildtypes.context import BuildOptions, PackageJob
from roc.engine.events import task_key
from roc.engine.jobserver import Jobserver
from roc.engine.process import TaskContext
from roc.engine.ready import Task
from roc.fsutil import write_text_atomic
from roc.idl.task import IdlGeneration, proto_directory
from roc.idl.task import cmake_arguments as idl_cmake_arguments
from roc.workspace.load import Workspace
from roc.workspace.package import Package

TYPE_CHECKING = False  # typing is not imported at run time (start-up time of every build)
if TYPE_CHECKING:
    from typing import Protocol

    from roc.builder.compiler_cache import CompilerCache
    from roc.remote_cache.cache import RemoteCache
    from roc.remote_cache.keys import RemoteKeys

    class RemoteBuilds(Protocol):
        """Where packages are built instead of here (roc.cluster.remote_build.ClusterBuilds)."""

        def action(self, build: _PackageBuild) -> Callable[[TaskContext], object]: ...


def plan_build(
    workspace: Workspace, options: BuildOptions, jobserver: Jobserver | None, weights: dict[str, float],
    remote: RemoteCache | None = None, compiler: CompilerCache | None = None, cluster: RemoteBuilds | None = None,
) -> list[Task]:
    """One ``build`` task per selected package, and one ``idl`` task before it for a package with
    protobuf sources. Whether a task is up to date is checked when it is dispatched (what it waits for
    done by then). With a ``remote`` cache, a package that is not up to date is first looked up there
    (the task's ``restore``), and uploaded after it is built when the cache is writable. A ``compiler``
    cache is the compiler launcher of every CMake package. With a ``cluster``, a package that is not
    up to date and not in the remote cache is built on the cluster (its task's action)."""
    selected = workspace.selected
    fingerprints = Fingerprints(workspace, options)
    remote_keys = None
    if remote is not None:
        from roc.remote_cache.keys import RemoteKeys

        remote_keys = RemoteKeys(fingerprints.environment, fingerprints.prefixes, options.build_base)
    forced = generation_forced(options)
    tasks = []
    for package in workspace.selected_in_order():
        dependencies = workspace.dependencies.in_order(package.name)
        build = _PackageBuild(package, dependencies, options, jobserver, fingerprints)
        build.remote, build.remote_keys, build.compiler = remote, remote_keys, compiler
        waits_for = {n for n in dependencies if n in selected}
        if proto_directory(build.source) is not None:
            idl = IdlGeneration(package.name, build.source, options.build_base / package.name, forced,
                                record=options.use_state)
            key = task_key("idl", package.name)
            tasks.append(Task(name=package.name, dependencies=set(), action=idl.run, kind="idl",
                              weight=weights.get(key, 1.0), check=idl.check))
            waits_for.add(key)
            build.cmake_args = idl_cmake_arguments(options.build_base / package.name)
        tasks.append(Task(
            name=package.name,
            dependencies=waits_for,
            action=cluster.action(build) if cluster is not None else build.run,
            weight=package_weight(weights.get(package.name), build.source, options.build_base / package.name),
            check=build.check,
            restore=build.restore if remote is not None else None,
        ))
    return tasks


class _PackageBuild:
    """The up-to-date check and the action of one package's build task."""

    def __init__(self, package: Package, dependencies: list[str], options: BuildOptions, jobserver: Jobserver | None,
                 fingerprints: Fingerprints):
        self.package, self.dependencies, self.options = package, dependencies, options
        self.source = fingerprints.source(package)
        self.prefix = package_prefix(options.install_base, package.name, options.merge_install)
        self.jobserver, self.fingerprints = jobserver, fingerprints
        self.state: PackageState | None = None
        self.cmake_args: list[str] = []  # roc's own CMake arguments (where the package's idl task writes)
        self.remote: RemoteCache | None = None
        self.remote_keys: RemoteKeys | None = None
        self.remote_key: str | None = None
        self.compiler: CompilerCache | None = None

    def check(self) -> list[str]:
        if not self.options.use_state:
            return forced_reasons(self.options)
        self.state = self.fingerprints.compute(self.package)
        if self.remote_keys is not None:  # also for an up-to-date package: its dependents need its key
            self.remote_key = self.remote_keys.key(self.package.name, self.state.parts)
        reasons = stale_reasons(self.package, self.state, self.options)
        if not reasons and self.state.cut_off():
            stored = self.state.stored
            write_state(self.options.build_base / self.package.name, self.state.fingerprint, self.state.files,
                        self.state.parts, self.remote_key, stored.get("interface"), self.state.interfaces)
            self.fingerprints.installed(self.package.name, stored.get("interface"))
        return reasons

    def restore(self, context: TaskContext) -> str | None:
        """Restore the package from the remote cache: None when done, else why not."""
        if self.remote is None or self.state is None or forced_reasons(self.options):
            return ""
        if self.remote_key is None:
            missing = self.remote_keys.missing_dependency(self.state.parts) if self.remote_keys else None
            return f"no remote cache key (dependency '{missing}' has none: build it with the remote cache on)"
        return self.fetch(context)

    def fetch(self, context: TaskContext) -> str | None:
        """Restore the package's remote key from the remote cache, recorded as built when whole: None
        when done, else why not."""
        assert self.remote is not None and self.state is not None and self.remote_key is not None
        build_dir = self.options.build_base / self.package.name
        write_state(build_dir, None, self.state.files)  # until restored whole
        missed = self.remote.restore(self.package, self.remote_key, context)
        if missed is None:
            self.record(build_dir, self.state.files)
        return missed

    def record(self, build_dir: Path, files: dict) -> None:
        """Record the package as built (or restored) as it is now, with the interface it installed."""
        assert self.state is not None
        interface = install_interface(self.package.name, self.fingerprints.workspace.root, self.options)
        write_state(build_dir, self.state.fingerprint, files, self.state.parts, self.remote_key, interface,
                    self.state.interfaces)
        self.fingerprints.installed(self.package.name, interface)

    def run(self, context: TaskContext) -> None:
        package, options = self.package, self.options
        env = build_environment(package, self.dependencies, options)
        cmake_args = self.cmake_args
        if self.compiler is not None and package.build_type in ("cmake", "ament_cmake"):
            env.update(self.compiler.environment)
            cmake_args = [*cmake_args, *self.compiler.cmake_arguments()]
        job = PackageJob(package=package, source=self.source, build_dir=options.build_base / package.name,
                         prefix=self.prefix, env=env, cmake_args=cmake_args)
        if self.jobserver is not None:
            job.make_flags = self.jobserver.makeflags(env.get("MAKEFLAGS", ""))
            job.pass_fds = self.jobserver.fds
        job.build_dir.mkdir(parents=True, exist_ok=True)
        files = self.state.files if self.state else {}
        # Until it succeeds (and even with --no-cache, which records no new one), no old fingerprint
        # may vouch for what this build is about to install.
        write_state(job.build_dir, None, files)
        write_text_atomic(job.build_dir / ENVIRONMENT_FILE, json.dumps(env, indent=1, sort_keys=True))
        build_function(package.type)(context, job, options)
        finish_package(package, job.prefix)
        if self.state is not None and not options.partial():
            self.record(job.build_dir, files)
            if self.remote is not None and self.remote.settings.writes and self.remote_key:
                self.remote.upload(package, self.remote_key, context)
