"""Turn the selected packages into engine tasks (kind ``test``) that test them, with cached results.

Whether a passing result is still valid is decided by each task's ``check``, when the task is
dispatched: it returns why the package must be tested again (``never tested``, ``files changed: ...``,
``--force``), or nothing for a cached result."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from roc.builder.environment import build_environment
from roc.builder.fingerprint import combine
from roc.buildtypes.context import BuildOptions
from roc.engine.events import task_key
from roc.engine.process import RanElsewhere, TaskContext
from roc.engine.ready import Task
from roc.testing.cache import (
    read_test_state,
    rerun_reasons,
    results_parts,
    write_test_state,
)
from roc.testing.results import collect_results
from roc.testing.runner import TestOptions, run_package_tests
from roc.workspace.load import Workspace
from roc.workspace.package import Package

KIND = "test"


# Runs a package's tests elsewhere (roc.cluster.remote_test): whether they all passed, and where they ran.
TestRunner = Callable[[TaskContext, "PackageTest"], tuple[bool, RanElsewhere | None]]


def plan_tests(workspace: Workspace, options: TestOptions, weights: dict[str, float], force: bool = False,
               use_cache: bool = True, runner: TestRunner | None = None) -> list[Task]:
    """One task per selected package, after the selected packages it depends on (as colcon orders
    tests); a ``runner`` runs them instead of this machine (a cluster)."""
    tasks = []
    for package in workspace.selected_in_order():
        dependencies = workspace.dependencies.in_order(package.name)
        test = PackageTest(package, (workspace.root / package.path).resolve(), dependencies, options, force,
                           use_cache)
        test.runner = runner
        key = task_key(KIND, package.name)
        tasks.append(Task(
            name=package.name,
            dependencies={task_key(KIND, n) for n in dependencies if n in workspace.selected},
            action=test.run,
            kind=KIND,
            weight=weights.get(key, 1.0),
            check=test.check,
        ))
    return tasks


class PackageTest:
    """One package's test task: ``check`` (at dispatch) computes the key of the run and says why it must
    run; ``run`` (in a worker) tests and records the outcome under that key."""

    __test__ = False

    def __init__(self, package: Package, source: Path, dependencies: list[str], options: TestOptions,
                 force: bool = False, use_cache: bool = True):
        self.package, self.source, self.dependencies, self.options = package, source, dependencies, options
        self.force, self.use_cache = force, use_cache
        self.build_dir = options.build_base / package.name
        self.parts: dict | None = None
        self.files: dict = {}
        self.runner: TestRunner | None = None

    def check(self) -> list[str]:
        if not self.use_cache:
            return ["--no-cache"]
        state = read_test_state(self.build_dir)
        self.parts, self.files = results_parts(self.source, self.options.build_base, self.package.name,
                                               self.dependencies, self.options.digest(), state)
        if self.force:
            return ["--force"]
        return rerun_reasons(state, self.parts)

    def run(self, context: TaskContext) -> RanElsewhere | None:
        self.build_dir.mkdir(parents=True, exist_ok=True)
        if self.use_cache:
            write_test_state(self.build_dir, None, False, self.files, [])
        passed, elsewhere = self.runner(context, self) if self.runner else (self.run_here(context), None)
        if self.use_cache:
            results: set[str] = set()
            collect_results(self.options.result_dir(self.package.name), files=results)
            key = combine(self.parts) if self.parts else None
            write_test_state(self.build_dir, key, passed, self.files, sorted(str(Path(p).absolute()) for p in results),
                             self.parts)
        return elsewhere

    def run_here(self, context: TaskContext) -> bool:
        """Run the package's tests on this machine; whether they all passed."""
        # For testing, the package's own install prefix is part of its environment (as in colcon).
        environment_options = BuildOptions(build_base=self.options.build_base,
                                           install_base=self.options.install_base,
                                           merge_install=self.options.merge_install)
        env = build_environment(self.package, [*self.dependencies, self.package.name], environment_options)
        return run_package_tests(context, self.package.type, self.package.name, self.source, env, self.options)
