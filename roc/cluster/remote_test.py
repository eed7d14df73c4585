"""Test tasks on the cluster (``roc work test --cluster``): a package's tests run on a worker, which
restores the package's dependencies from the remote cache, builds the package there (CTest needs its
build tree; a Python package is restored) and uploads its result files; they come back into
``<build-base>/<pkg>/`` (or ``--test-result-base``) as a local run leaves them, so ``roc work
test-result`` and the cached test results work unchanged.

A package is tested here, with a warning saying why, when it or a dependency has no remote key (it
was built without the remote cache).
"""

from __future__ import annotations

import shutil
import tempfile
import uuid
from pathlib import Path
from typing import TYPE_CHECKING

from roc.builder.fingerprint import source_stamps
from roc.builder.state import read_state
from roc.cluster import work as on_worker
from roc.cluster.client import Cluster
from roc.cluster.files import RESULT_FILES, pack_files, remove_path, unpack_files
from roc.cluster.remote_build import plain_package
from roc.cluster.spec import PackageWork
from roc.engine.events import TaskWarning
from roc.engine.process import RanElsewhere, TaskContext, TaskError
from roc.fsutil import file_sha256
from roc.remote_cache.store import StoreUnavailable

if TYPE_CHECKING:
    from roc.remote_cache.cache import RemoteCache
    from roc.testing.plan import PackageTest
    from roc.workspace.load import Workspace

class ClusterTests:
    """The runner of a run's test tasks (roc.testing.plan.TestRunner) on the cluster."""

    def __init__(self, cluster: Cluster, workspace: Workspace, remote: RemoteCache):
        self.cluster, self.workspace, self.remote = cluster, workspace, remote

    def __call__(self, context: TaskContext, test: PackageTest) -> tuple[bool, RanElsewhere | None]:
        keys = {name: read_state(test.options.build_base / name).get("remote_key")
                for name in [*test.dependencies, test.package.name]}
        without = [name for name, key in keys.items() if not key]
        if without:
            context.emit(TaskWarning(context.name, context.kind, message=(
                f"tested here, not on the cluster: {without[0]} has no remote key (build with --remote-cache or "
                "--cluster first)")))
            with self.cluster.here():  # on the client's cores, beside the workers' slots
                return test.run_here(context), None
        work = self._work(test, keys)
        result = self.cluster.run(on_worker.test, work, f"roc-test-{work.key}-{uuid.uuid4().hex[:8]}", context)
        for event in result.events:
            context.emit(event.for_task(context.name, context.kind))
        if not result.ok or result.results is None:
            raise TaskError(result.reason or "no test results")
        self._fetch_results(result.results, test.options.result_dir(test.package.name))
        return bool(result.passed), RanElsewhere(result.worker, result.duration)

    def _work(self, test: PackageTest, keys: dict[str, str | None]) -> PackageWork:
        options = test.options
        files = test.files or source_stamps(test.source, {})
        built = read_state(options.build_base / test.package.name).get("parts") or {}
        built_with = built.get("options", {})  # the CMake arguments of its build here, for the build there
        return PackageWork(
            package=plain_package(test.package),
            dependencies=[(plain_package(self.workspace.by_name[name]), keys[name] or "")
                          for name in test.dependencies],
            key=keys[test.package.name] or "",
            portable={},
            sources=pack_files(test.source, files),
            options={"merge_install": options.merge_install, "cmake_args": tuple(built_with.get("cmake-args", ())),
                     "ament_cmake_args": tuple(built_with.get("ament-cmake-args", ()))},
            cache_url=self.remote.settings.shown,
            cache_timeout=self.remote.settings.timeout,
            toolchain=self.cluster.toolchain,
            toolchain_parts=self.cluster.toolchain_parts,
            test={"ctest_args": options.ctest_args, "pytest_args": options.pytest_args,
                  "pytest_with_coverage": options.pytest_with_coverage,
                  "retest_until_fail": options.retest_until_fail, "retest_until_pass": options.retest_until_pass},
        )

    def _fetch_results(self, sha256: str, result_dir: Path) -> None:
        """Download the result files' archive, check it, and put its files where a local run would."""
        with tempfile.TemporaryDirectory(prefix=".roc-results-", dir=result_dir.parent) as temporary:
            archive = Path(temporary) / "results.tar.gz"
            try:
                found = self.remote.store().get(f"cas/{sha256}", archive)
            except StoreUnavailable as error:
                raise TaskError(f"remote cache {self.remote.settings.shown}: {error}") from None
            if not found or file_sha256(archive) != sha256:
                raise TaskError(f"the test results ({sha256[:12]}) are not whole in the remote cache")
            unpacked = Path(temporary) / "results"
            unpack_files(archive.read_bytes(), unpacked)
            result_dir.mkdir(parents=True, exist_ok=True)
            for name in {*RESULT_FILES, *(item.name for item in unpacked.iterdir())}:
                remove_path(result_dir / name)  # the results of an earlier run here
                if (unpacked / name).exists():
                    shutil.move(unpacked / name, result_dir / name)
