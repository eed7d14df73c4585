"""Turn the selected packages into engine tasks that test them, with cached results."""

from __future__ import annotations

from pathlib import Path

from roc.builder.environment import build_environment
from roc.buildtypes.context import BuildOptions
from roc.engine.process import TaskContext
from roc.engine.ready import Task
from roc.testing.cache import passed_before, read_test_state, results_key, write_test_state
from roc.testing.results import collect_results
from roc.testing.runner import TestOptions, run_package_tests
from roc.workspace.dependencies import recursive_dependencies
from roc.workspace.load import Workspace
from roc.workspace.package import Package


def plan_tests(workspace: Workspace, options: TestOptions, weights: dict[str, float], force: bool = False,
               use_cache: bool = True) -> list[Task]:
    """One task per selected package, after the selected packages it depends on (as colcon orders
    tests); a package that passed before with the same key is up to date (cached)."""
    by_name = workspace.by_name
    order = [p.name for p in workspace.ordered]
    tasks = []
    for package in workspace.selected_in_order():
        recursive = recursive_dependencies(package, by_name)
        dependencies = [n for n in order if n in recursive]
        source = (workspace.root / package.path).resolve()
        key, files, cached = None, {}, False
        if use_cache:
            state = read_test_state(options.build_base / package.name)
            key, files = results_key(source, options.build_base, package.name, dependencies, options.digest(), state)
            cached = not force and passed_before(state, key)
        tasks.append(Task(
            name=package.name,
            dependencies={n for n in dependencies if n in workspace.selected},
            action=_test_action(package, source, dependencies, options, key if use_cache else None, files,
                                use_cache),
            weight=weights.get(package.name, 1.0),
            check=lambda cached=cached: [] if cached else ["not passed before"],
        ))
    return tasks


def _test_action(package: Package, source: Path, dependencies: list[str], options: TestOptions, key: str | None,
                 files: dict, use_cache: bool):
    environment_options = BuildOptions(build_base=options.build_base, install_base=options.install_base,
                                       merge_install=options.merge_install)

    def action(context: TaskContext) -> None:
        # For testing, the package's own install prefix is part of its environment (as in colcon).
        env = build_environment(package, [*dependencies, package.name], environment_options)
        build_dir = options.build_base / package.name
        build_dir.mkdir(parents=True, exist_ok=True)
        if use_cache:
            write_test_state(build_dir, None, False, files, [])
        passed = run_package_tests(context, package.type, package.name, source, env, options)
        if use_cache:
            results: set[str] = set()
            collect_results(options.result_dir(package.name), files=results)
            write_test_state(build_dir, key, passed, files, sorted(str(Path(p).absolute()) for p in results))

    return action
