"""``roc work test``: test the workspace's packages, a drop-in for ``colcon test``, with cached results."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from roc.cli.options import (
    AppendToCommandLine,
    add_base_arguments,
    add_selection_arguments,
)
from roc.engine.events import Event, TestFailures, TestsNotRun
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, UsageError
from roc.handlers import add_event_handlers_argument, handler_switches, output_handlers

DURATIONS_FILE = "roc_test_durations.json"
CACHED_LABEL = "cached (passed before, not tested again)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add = parser.add_argument
    add("packages", nargs="*", metavar="PKG_NAME", help="shorthand for --packages-select PKG_NAME...")
    add_base_arguments(parser)
    add("--test-result-base", help="the base path of all test results (default: --build-base)")
    add("--log-base", default="log", help="base directory of the logs, or /dev/null for none (default: log)")
    retest = parser.add_mutually_exclusive_group()
    retest.add_argument("--retest-until-fail", type=int, default=0, metavar="N",
                        help="rerun the tests up to N times while they pass")
    retest.add_argument("--retest-until-pass", type=int, default=0, metavar="N",
                        help="rerun failing tests up to N times")
    add("--abort-on-error", action="store_true",
        help="stop at the first package with an error (failing tests are not errors here)")
    add("--return-code-on-test-failure", action="store_true", help="exit non-zero when any test failed")
    add("--ctest-args", action=AppendToCommandLine, metavar="ARG", default=[],
        help="arguments for CTest (values may start with '-')")
    add("--pytest-args", action=AppendToCommandLine, metavar="ARG",
        help="arguments for pytest (values may start with '-')")
    add("--pytest-with-coverage", action="store_true", help="collect coverage of Python packages (pytest-cov)")
    add("--executor", choices=("parallel", "sequential"), default="parallel",
        help="test packages in parallel (default) or one at a time")
    add("--parallel-workers", type=int, metavar="NUMBER", default=os.cpu_count() or 1,
        help="packages tested at once, 0 for no limit (default: the number of CPUs)")
    add_event_handlers_argument(parser)
    add("--output", choices=("text", "json"), default="text", help="json: one JSON event per line on stdout")
    add("--force", action="store_true", help="test the selected packages even when their results are cached")
    add("--no-cache", action="store_true", help="neither reuse passing results nor record them")
    from roc.cluster.settings import add_cluster_argument

    add_cluster_argument(parser, "run the tests")
    add("--remote-cache", metavar="URL", help="with --cluster: the remote build cache the workers restore the "
        "packages from and send the results through (default: $ROC_REMOTE_CACHE)")
    add_selection_arguments(parser)


class TestOutcomes:
    """Which tasks' tests failed (for ``[ with test failures ]`` and the exit code), and which ran none
    and why (``[ no tests ran: ... ]``)."""

    __test__ = False

    def __init__(self) -> None:
        self.keys: set[str] = set()
        self.not_run: dict[str, str] = {}

    def __call__(self, event: Event) -> None:
        if isinstance(event, TestFailures):
            self.keys.add(event.key)
        elif isinstance(event, TestsNotRun):
            self.not_run[event.key] = event.reason

    def note(self, key: str) -> str:
        """What the console adds to the task's ``Finished`` line."""
        if key in self.keys:
            return "\t[ with test failures ]"
        if key not in self.not_run:
            return ""
        return f"\t[ no tests ran{': ' + self.not_run[key] if self.not_run[key] else ''} ]"


def _options(args: argparse.Namespace, root: Path):
    from roc.testing.runner import TestOptions

    build_base = (root / args.build_base).absolute()
    return TestOptions(
        build_base=build_base, install_base=(root / args.install_base).absolute(), merge_install=args.merge_install,
        test_result_base=(root / args.test_result_base).absolute() if args.test_result_base else None,
        ctest_args=tuple(args.ctest_args), pytest_args=tuple(args.pytest_args) if args.pytest_args is not None
        else None, pytest_with_coverage=args.pytest_with_coverage, retest_until_fail=args.retest_until_fail,
        retest_until_pass=args.retest_until_pass,
    )


def _skip_untestable(workspace) -> None:
    from roc.messages import warn
    from roc.testing.runner import testable

    for package in workspace.selected_in_order():
        if not testable(package.type):
            warn(f"{package.path}: no way to test '{package.name}' of type '{package.type}'; skipped")
            workspace.selected.discard(package.name)


def run(args: argparse.Namespace) -> int:
    from roc.commands.work.build import skip_configured_packages
    from roc.workspace.load import load_workspace

    switches = handler_switches(args.event_handlers)
    if args.packages:
        args.packages_select = [*(args.packages_select or []), *args.packages]
    if args.parallel_workers < 0:
        raise UsageError("--parallel-workers must be 0 (no limit) or more")
    if args.retest_until_fail < 0 or args.retest_until_pass < 0:
        raise UsageError("--retest-until-fail/--retest-until-pass must be 0 or more")
    workspace = load_workspace(args)
    skip_configured_packages(args, workspace)
    _skip_untestable(workspace)
    options = _options(args, workspace.root)
    workers = 1 if args.executor == "sequential" else args.parallel_workers
    cluster = _cluster(args, workspace, options)
    try:
        return _test(args, workspace, options, switches, workers, cluster)
    finally:
        if cluster is not None:
            cluster.cluster.close()


def _cluster(args: argparse.Namespace, workspace, options):
    """The run's ClusterTests with --cluster (one line when the scheduler cannot be reached or no worker
    fits, before anything runs), else None."""
    from roc.cluster.settings import cluster_address
    from roc.commands.work.build import remote_cache

    remote = remote_cache(args, workspace, options)
    address = cluster_address(args, remote)
    if address is None or not _anything_to_test(args, workspace, options):
        return None  # cached results only: the cluster is not asked (nor Dask loaded)
    from roc.cluster.client import connect
    from roc.cluster.remote_test import ClusterTests

    return ClusterTests(connect(address, options.install_base), workspace, remote)


def _anything_to_test(args: argparse.Namespace, workspace, options) -> bool:
    from roc.testing.plan import plan_tests

    return any(task.check is None or task.check()
               for task in plan_tests(workspace, options, {}, force=args.force, use_cache=not args.no_cache))


def _test(args: argparse.Namespace, workspace, options, switches: dict[str, bool], workers: int, cluster) -> int:
    from roc.builder.layout import prepare_build_base, prepare_install_base
    from roc.builder.lock import build_lock
    from roc.engine.executor import execute
    from roc.engine.store import DurationStore
    from roc.testing.plan import KIND, plan_tests

    with build_lock(options.build_base):
        prepare_build_base(options.build_base)
        prepare_install_base(options.install_base, args.merge_install)
        durations = DurationStore(options.build_base / DURATIONS_FILE)
        failures = TestOutcomes()
        handlers = [*output_handlers(args, switches, workspace.root, options.build_base, verb="test",
                                     cached_label=CACHED_LABEL, finished_note=failures.note),
                    failures, durations]
        try:
            tasks = plan_tests(workspace, options, durations.durations, force=args.force, use_cache=not args.no_cache,
                               runner=cluster)
            limit = workers if cluster is None else cluster.cluster.task_limit(workers)
            result = execute(tasks, handlers, limit, continue_on_error=not args.abort_on_error, kind=KIND)
        finally:
            for handler in handlers:
                getattr(handler, "close", lambda: None)()
        durations.save()
    if result.interrupted:
        return EXIT_INTERRUPTED
    if not result.ok:
        return EXIT_FAILURE
    return EXIT_FAILURE if args.return_code_on_test_failure and failures.keys else 0
