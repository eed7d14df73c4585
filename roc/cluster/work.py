"""What a worker does with one package (a ``PackageWork``), in the Dask task's thread: check that it
has the client's toolchain, make a workspace of its own in the work root, restore the package's
dependencies from the remote cache, then build (or test) the package with roc's ordinary engine and
build types (roc.builder.plan, roc.testing.plan: the code path of a local build), upload what it
built, and say what happened (a ``WorkResult``: the commands and their output as events, the
duration, the worker's name).

Nothing here raises for a failure of the work itself (a refused toolchain, a dependency the cache
does not have, a full disk, a failed compile): each is a WorkResult with the reason, which the client
shows as it shows a local failure. The client cancelling the task (Ctrl+C, or the client gone) stops
the running commands' whole process trees.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from pathlib import Path

from roc.builder.artefact import Places, installed_files, path_dependent_file
from roc.builder.layout import package_prefix
from roc.builder.state import install_intact, read_state, write_state
from roc.buildtypes.context import BuildOptions
from roc.cluster.files import RESULT_FILES, pack_files, remove_path, unpack_files
from roc.cluster.spec import PackageWork, WorkResult
from roc.cluster.toolchain import BUILD_RESOURCE, differences, fingerprint_parts, machine_fingerprint
from roc.cluster.workroot import WorkRoot
from roc.engine.events import (
    CommandEnded,
    CommandStarted,
    Event,
    TaskFailed,
    TaskOutput,
    TaskWarning,
    TestFailures,
)
from roc.engine.executor import execute
from roc.engine.process import TaskContext
from roc.fsutil import file_sha256
from roc.remote_cache.cache import RemoteCache
from roc.remote_cache.settings import RemoteSettings
from roc.workspace.load import Workspace
from roc.workspace.package import Package

KEPT_EVENTS = (CommandStarted, CommandEnded, TaskOutput, TaskWarning, TestFailures)
CANCEL_POLL_SECONDS = 0.25
CLOSING = ("closing", "closed", "failed")  # a worker's distributed.core.Status names once it is going away


class WorkFailed(Exception):
    """The work cannot go on; the message says why (the WorkResult's reason)."""

    def __init__(self, message: str, refused: bool = False):
        super().__init__(message)
        self.refused = refused


class _Recorder:
    """An event handler keeping what the client shows of the work (the commands and their output, warnings,
    test failures) and why a task failed."""

    def __init__(self) -> None:
        self.events: list[Event] = []
        self.failures: list[str] = []

    def __call__(self, event: Event) -> None:
        if isinstance(event, KEPT_EVENTS):
            self.events.append(event)
        elif isinstance(event, TaskFailed):
            self.failures.append(event.reason.strip() or "failed")


def build(work: PackageWork) -> WorkResult:
    """The Dask task of a package's build."""
    return _Work(work).run(test=False)


def test(work: PackageWork) -> WorkResult:
    """The Dask task of a package's tests."""
    return _Work(work).run(test=True)


def _current_worker():
    from distributed import get_worker
    from distributed.worker import thread_state

    return get_worker(), thread_state.key


class _Work:
    def __init__(self, work: PackageWork):
        self.work = work
        self.recorder = _Recorder()
        self.stop = threading.Event()
        self.worker, self.key = _current_worker()
        self.name = str(self.worker.name)

    def run(self, test: bool) -> WorkResult:
        start = time.monotonic()
        finished = threading.Event()
        threading.Thread(target=self._watch_cancel, args=(finished,), daemon=True).start()
        result: dict = {"ok": False, "reason": f"worker {self.name} gave no result"}
        try:
            root = getattr(self.worker, "roc_work_root", None)
            if not isinstance(root, WorkRoot):
                raise WorkFailed(f"worker {self.name} was not started for roc (roc work worker, or dask worker "
                                 "--preload roc.cluster.worker)", refused=True)
            self._check_toolchain(root)
            with root.slot(self.work.name) as folder:
                result = self._test(folder) if test else self._build(folder)
        except WorkFailed as error:
            result = {"ok": False, "reason": str(error), "refused": error.refused}
        except OSError as error:  # a full disk, a folder it may not write
            where = f" ({error.filename})" if error.filename else ""
            result = {"ok": False, "reason": f"on worker {self.name}: {error.strerror or error}{where}"}
        except Exception as error:  # noqa: BLE001 - a bug: the package fails with it, its traceback in the worker's log
            logging.getLogger("distributed.worker").exception("roc: %s failed", self.work.name)
            result = {"ok": False, "reason": f"worker {self.name}: internal error: {type(error).__name__}: {error}"}
        finally:
            finished.set()
        return WorkResult(key=self.work.key, worker=self.name, duration=time.monotonic() - start,
                          events=self.recorder.events, **result)

    def _watch_cancel(self, finished: threading.Event) -> None:
        """Stop the work when the scheduler released its task (the client cancelled it, or is gone), or when
        the worker closes (its scheduler stopped or was lost: nobody waits for the result any more)."""
        while not finished.wait(CANCEL_POLL_SECONDS):
            state = self.worker.state.tasks.get(self.key)
            if (state is None or state.state not in ("executing", "long-running")
                    or self.worker.status.name in CLOSING):
                self.stop.set()
                return

    def _check_toolchain(self, root: WorkRoot) -> None:
        if machine_fingerprint(root.root) != self.work.toolchain:
            from roc.builder.environment import base_environment

            changed = differences(fingerprint_parts(base_environment(), root.root), self.work.toolchain_parts)
            raise WorkFailed(f"worker {self.name} refused it: its toolchain differs from the client's "
                             f"({', '.join(changed[:4]) or 'fingerprint'})", refused=True)

    # ------------------------------------------------------------------------------- the workspace

    def _workspace(self, folder: Path) -> tuple[Workspace, BuildOptions, RemoteCache]:
        """A workspace in ``folder`` with the package's sources and its dependencies restored."""
        work = self.work
        packages = [_package(data) for data, _ in work.dependencies] + [_package(work.package)]
        remove_path(folder / "src" / work.name)  # the sources of an earlier task on this package
        unpack_files(work.sources, folder / "src" / work.name)
        workspace = Workspace(folder, packages, {work.name})
        slots = max(1, int(self.worker.state.total_resources.get(BUILD_RESOURCE, 1)))
        jobs = max(1, len(os.sched_getaffinity(0)) // slots)  # its share of this worker's cores (taskset)
        options = BuildOptions(build_base=folder / "build", install_base=folder / "install", jobs=jobs,
                               jobs_per_package=jobs, **work.options)
        settings = RemoteSettings(work.cache_url, "read-write", work.cache_timeout)  # the only way back
        remote = RemoteCache(settings, Places(folder, options.build_base, options.install_base),
                             options.merge_install)
        for (_, key), package in zip(work.dependencies, packages):
            self._restore(remote, package, key, options)
        return workspace, options, remote

    def _restore(self, remote: RemoteCache, package: Package, key: str, options: BuildOptions) -> None:
        build_dir = options.build_base / package.name
        prefix = package_prefix(options.install_base, package.name, options.merge_install)
        if read_state(build_dir).get("remote_key") == key and install_intact(prefix, package.name, build_dir):
            return  # restored (or built) in this workspace by an earlier task
        context = TaskContext(package.name, self.recorder, "build")
        missed = remote.restore(package, key, context)
        if missed is not None:
            what = package.name if package.name == self.work.name else f"the dependency {package.name}"
            raise WorkFailed(f"worker {self.name} could not restore {what}: {missed}")
        state = read_state(build_dir)
        write_state(build_dir, state.get("fingerprint"), state.get("files", {}), state.get("parts"), key,
                    state.get("interface"), state.get("interfaces"))

    # ----------------------------------------------------------------------------------- a build

    def _build(self, folder: Path) -> dict:
        from roc.builder.plan import plan_build
        from roc.engine.jobserver import Jobserver

        workspace, options, remote = self._workspace(folder)
        compiler = self._compiler_cache(folder, options, remote)
        jobserver = Jobserver(options.jobs)
        try:
            tasks = plan_build(workspace, options, jobserver, {}, remote, compiler)
            mismatch = self._expect_key(tasks)
            execute(tasks, [self.recorder], 1, stop=self.stop)
        finally:
            jobserver.close()
            if compiler is not None:
                compiler.finish()
        if mismatch:
            raise WorkFailed(mismatch[0], refused=True)
        if self.recorder.failures:
            return {"ok": False, "reason": self.recorder.failures[-1]}
        if self.stop.is_set():
            return {"ok": False, "reason": "cancelled"}
        return self._check_upload(workspace, options, remote)

    def _check_upload(self, workspace: Workspace, options: BuildOptions, remote: RemoteCache) -> dict:
        """The package is in the remote cache under its key (uploaded now if it was up to date here, built
        by an earlier task, and its entry has gone since), or its files hold this folder's path."""
        from roc.remote_cache.store import StoreUnavailable

        key, name, places = self.work.key, self.work.name, remote.places
        try:
            uploaded = remote.unavailable is None and remote.store().exists(f"ac/{key}")
            if not uploaded and remote.unavailable is None:
                bound = path_dependent_file(installed_files(name, places, options.merge_install),
                                            places.install_base, places)
                if bound:  # uploaded under the key placed at this folder
                    return {"ok": True, "bound": bound}
                remote.upload(workspace.by_name[name], key, TaskContext(name, self.recorder))
                uploaded = remote.unavailable is None and remote.store().exists(f"ac/{key}")
        except StoreUnavailable as error:
            remote.unavailable = str(error)
        if not uploaded:
            raise WorkFailed(f"worker {self.name} could not upload it: remote cache {remote.settings.shown}: "
                             f"{remote.unavailable or 'the entry is not there'}")
        return {"ok": True}

    def _expect_key(self, tasks) -> list[str]:
        """Make the package's build task check, before it builds, that its remote key here is the
        client's; a mismatch (any part of the toolchain or the sources) is noted and fails the task."""
        build_task = next(t for t in tasks if t.kind == "build" and t.name == self.work.name)
        check, build = build_task.check, build_task.check.__self__
        mismatch: list[str] = []

        def checked() -> list[str]:
            reasons = check()
            if build.remote_key != self.work.key:
                portable = build.remote_keys.portable_parts(build.state.parts) if build.state else None
                changed = differences(portable or {}, self.work.portable)
                mismatch.append(f"worker {self.name} refused it: the package's remote key differs here "
                                f"({', '.join(changed[:4]) or 'a dependency has none'})")
                raise WorkFailed(mismatch[0], refused=True)
            return reasons or ["built for the cluster"]

        build_task.check = checked
        return mismatch

    def _compiler_cache(self, folder: Path, options: BuildOptions, remote: RemoteCache):
        if not self.work.compiler_cache:
            return None
        from roc.builder.compiler_cache import compiler_cache

        return compiler_cache(self.work.compiler_cache, None, folder, options.build_base, remote.settings)

    # ----------------------------------------------------------------------------------- a test

    def _test(self, folder: Path) -> dict:
        from roc.testing.plan import plan_tests
        from roc.testing.runner import TestOptions

        work = self.work
        assert work.test is not None
        workspace, options, remote = self._workspace(folder)
        package = workspace.by_name[work.name]
        if package.build_type in ("cmake", "ament_cmake"):
            self._build_tree(workspace, options)  # CTest runs in the package's build tree
        else:
            self._restore(remote, package, work.key, options)
        test_options = TestOptions(build_base=options.build_base, install_base=options.install_base,
                                   merge_install=options.merge_install, **work.test)
        result_dir = test_options.result_dir(work.name)
        for stale in RESULT_FILES:  # the results of an earlier test in this folder
            remove_path(result_dir / stale)
        tasks = plan_tests(workspace, test_options, {}, force=True, use_cache=False)
        execute(tasks, [self.recorder], 1, kind="test", stop=self.stop)
        if self.recorder.failures:
            return {"ok": False, "reason": self.recorder.failures[-1]}
        if self.stop.is_set():
            return {"ok": False, "reason": "cancelled"}
        from roc.testing.results import collect_results

        found: set[str] = set()
        collect_results(result_dir, files=found)
        tag = result_dir / "Testing" / "TAG"
        names = {str(Path(path).relative_to(result_dir)) for path in found | ({str(tag)} if tag.is_file() else set())}
        archive = folder / ".roc-test-results.tar.gz"
        archive.write_bytes(pack_files(result_dir, names))
        sha256 = file_sha256(archive)
        from roc.remote_cache.store import StoreUnavailable

        try:
            if not remote.store().exists(f"cas/{sha256}"):
                remote.store().put(f"cas/{sha256}", archive)
        except StoreUnavailable as error:
            raise WorkFailed(f"worker {self.name} could not upload the test results: remote cache "
                             f"{remote.settings.shown}: {error}") from None
        passed = not any(isinstance(event, TestFailures) for event in self.recorder.events)
        return {"ok": True, "passed": passed, "results": sha256}

    def _build_tree(self, workspace: Workspace, options: BuildOptions) -> None:
        """Build the package here without the remote cache (a build tree, not an install, is wanted);
        nothing to do in the folder of this key's build. A package this folder only restored (a dependency
        of another package built here) has an install and a state but no build tree: its state goes, so
        it is built."""
        from roc.builder.plan import plan_build
        from roc.builder.state import STATE_FILE

        build_dir = options.build_base / self.work.name
        if not (build_dir / "CMakeCache.txt").is_file():
            (build_dir / STATE_FILE).unlink(missing_ok=True)

        execute(plan_build(workspace, options, None, {}), [self.recorder], 1, stop=self.stop)
        if self.recorder.failures:
            raise WorkFailed(f"building it for its tests failed: {self.recorder.failures[-1]}")


def _package(data: dict) -> Package:
    """A package of the client's workspace, its sources at ``src/<name>`` here."""
    return Package.from_dict({**data, "path": f"src/{data['name']}", "manifest": None})
