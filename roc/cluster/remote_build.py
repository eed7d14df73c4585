"""The action of a build task on the cluster (``roc work build --cluster``).

The engine runs a build task as always: its check (up to date?) and its restore step (in the remote
cache?) happen here. Only when both miss does this action send the package to the cluster, wait for
it, show the worker's commands and output as this task's, and restore what the worker uploaded into
the install base, as from the cache; the task then finishes ``[12.3s on worker-2]``.

A package that cannot travel is built here instead, with a warning saying why: with
``--symlink-install`` (its install points into the sources) or ``--cmake-target`` (a partial build),
without a remote key, when its archive holds the path it was built at (it could only be restored at
the worker's path), and when a dependency was built here for one of these reasons.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from roc.builder.state import read_state
from roc.cluster import work as on_worker
from roc.cluster.client import OnDemand
from roc.cluster.files import pack_files
from roc.cluster.spec import PackageWork
from roc.engine.events import TaskWarning
from roc.engine.process import RanElsewhere, TaskContext, TaskError

if TYPE_CHECKING:
    from roc.builder.plan import _PackageBuild
    from roc.cluster.client import Cluster
    from roc.remote_cache.cache import RemoteCache
    from roc.workspace.load import Workspace


class ClusterBuilds:
    """A run's builds on the cluster: the action of each build task, and what was built here."""

    def __init__(self, cluster: OnDemand, workspace: Workspace, remote: RemoteCache, compiler_cache: str | None = None):
        self.cluster, self.workspace, self.remote, self.compiler_cache = cluster, workspace, remote, compiler_cache
        self.here: dict[str, str] = {}  # packages built here, and why (their dependents are built here too)

    def action(self, build: _PackageBuild) -> Callable[[TaskContext], RanElsewhere | None]:
        return lambda context: self.run(build, context)

    def run(self, build: _PackageBuild, context: TaskContext) -> RanElsewhere | None:
        why = self._stays_here(build)
        if why:
            self._here(build, context, why)
            return None
        assert build.remote_key is not None and build.state is not None and build.remote_keys is not None
        cluster = self.cluster.get()
        result = cluster.run(on_worker.build, self._work(build, cluster), f"roc-build-{build.remote_key}", context)
        for event in result.events:
            context.emit(event.for_task(context.name, context.kind))
        if not result.ok:
            raise TaskError(result.reason)
        if result.bound:
            self._here(build, context, f"built on {result.worker}, its archive holds the path it was built at "
                                       f"({result.bound})")
            return None
        missed = build.fetch(context)
        if missed is not None:
            self._here(build, context, f"built on {result.worker}, but not restored from the remote cache: {missed}")
            return None
        return RanElsewhere(result.worker, result.duration)

    def _here(self, build: _PackageBuild, context: TaskContext, why: str) -> None:
        self.here[build.package.name] = why
        context.emit(TaskWarning(context.name, context.kind, message=f"built here, not on the cluster: {why}"))
        with self.cluster.here():  # on the client's cores, beside the workers' slots
            build.run(context)

    def _stays_here(self, build: _PackageBuild) -> str | None:
        options = build.options
        if options.symlink_install:
            return "--symlink-install installs links into the sources"
        if options.partial():
            return "--cmake-target builds part of it"
        if build.remote_key is None:
            return "it has no remote key (--no-cache, or a dependency has none)"
        for dependency in build.dependencies:
            if dependency in self.here:
                return f"it depends on {dependency}, built here"
        return None

    def _work(self, build: _PackageBuild, cluster: Cluster) -> PackageWork:
        assert build.state is not None and build.remote_keys is not None and build.remote_key is not None
        name, options, keys = build.package.name, build.options, build.remote_keys
        dependencies = []
        for dependency in build.dependencies:
            key = keys.dependency_key(dependency) or read_state(options.build_base / dependency).get("remote_key", "")
            dependencies.append((plain_package(self.workspace.by_name[dependency]), key))
        return PackageWork(
            package=plain_package(build.package),
            dependencies=dependencies,
            key=build.remote_key,
            portable=keys.portable_parts(build.state.parts) or {},
            sources=pack_files(build.source, build.state.files),
            options={"merge_install": options.merge_install, "cmake_args": options.cmake_args,
                     "ament_cmake_args": options.ament_cmake_args,
                     "package_cmake_args": {name: options.package_cmake_args.get(name, ())},
                     "package_ament_cmake_args": {name: options.package_ament_cmake_args.get(name, ())},
                     "force": options.force},
            cache_url=self.remote.settings.shown,
            cache_timeout=self.remote.settings.timeout,
            toolchain=cluster.toolchain,
            toolchain_parts=cluster.toolchain_parts,
            compiler_cache=self.compiler_cache,
            force=options.force,
        )


def plain_package(package) -> dict:
    """A package as plain data, without its manifest (a worker needs its name, type, dependencies and hooks)."""
    return {**package.to_dict(), "manifest": None}

