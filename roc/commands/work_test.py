"""``roc work test``: test the workspace's packages, a drop-in for ``colcon test``, with cached results."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from roc.cli.options import AppendToCommandLine, add_base_arguments, add_selection_arguments
from roc.engine.events import Event, RunFinished, TaskAborted, TaskFailed, TaskFinished
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, UsageError
from roc.fsutil import write_text_atomic
from roc.render import print_lines
from roc.workspace.selection import INTERRUPTED_RESULT

DURATIONS_FILE = "roc_test_durations.json"
TEST_FAILURE_RESULT = "test failures"


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
    add("--event-handlers", nargs="*", metavar="NAME+/-", default=[],
        help="enable (+) or disable (-) output: console_start_end, console_stderr, console_direct, "
             "console_cohesion, summary, status, log, event_log, store_result")
    add("--output", choices=("text", "json"), default="text", help="json: one JSON event per line on stdout")
    add("--force", action="store_true", help="test the selected packages even when their results are cached")
    add("--no-cache", action="store_true", help="neither reuse passing results nor record them")
    add_selection_arguments(parser, previous_test=True)


class TestResults:
    """Each package's result in ``<build-base>/<pkg>/colcon_test.rc`` (as colcon writes it), and the
    packages with test failures (named in the summary)."""

    __test__ = False

    def __init__(self, build_base: Path, store: bool, summary: bool):
        self.build_base, self.store, self.summary = build_base, store, summary
        self.failures: set[str] = set()

    def __call__(self, event: Event) -> None:
        from roc.testing.runner import TestFailures

        if isinstance(event, TestFailures):
            self.failures.add(event.task)
        results = {TaskFinished: "0", TaskFailed: "1", TaskAborted: INTERRUPTED_RESULT}
        result = results.get(type(event))
        if result is not None and self.store:
            if result == "0" and event.task in self.failures:
                result = TEST_FAILURE_RESULT
            write_text_atomic(self.build_base / event.task / "colcon_test.rc", result + "\n")
        if isinstance(event, RunFinished) and self.summary and self.failures:
            count = len(self.failures)
            print_lines([f"  {count} package{'' if count == 1 else 's'} had test failures: "
                         f"{' '.join(sorted(self.failures))}"])


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


def _handlers(args, switches: dict[str, bool], root: Path, results: TestResults) -> list:
    from roc.handlers.console import ConsoleHandler
    from roc.handlers.logs import JsonEventsHandler, LogHandler, new_log_directory

    handlers: list = []
    log_dir = None
    if args.log_base != os.devnull and switches.get("log", True):
        log_dir = new_log_directory((root / args.log_base).absolute(), "test")
        handlers.append(LogHandler(log_dir, events=switches.get("event_log", True)))
    if args.output == "json":
        handlers.append(JsonEventsHandler(sys.stdout))
    else:
        status = None
        if switches.get("status", True) and sys.stdout.isatty() and not os.environ.get("NO_COLOR"):
            from roc.handlers.status import StatusLine

            status = StatusLine()
        handlers.append(ConsoleHandler(
            start_end=switches.get("console_start_end", True), stderr=switches.get("console_stderr", True),
            summary=switches.get("summary", True), direct=switches.get("console_direct", False),
            cohesion=switches.get("console_cohesion", False), log_path=str(log_dir) if log_dir else None,
            status=status, cached_label="cached (passed before, not tested again)",
            finished_note=lambda name: "\t[ with test failures ]" if name in results.failures else "",
        ))
    return handlers


def run(args: argparse.Namespace) -> int:
    from roc.builder.layout import prepare_build_base, prepare_install_base
    from roc.builder.lock import build_lock
    from roc.commands.work_build import skip_configured_packages
    from roc.handlers import handler_switches
    from roc.engine.executor import execute
    from roc.engine.store import DurationStore
    from roc.testing.plan import plan_tests
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
    with build_lock(options.build_base):
        prepare_build_base(options.build_base)
        prepare_install_base(options.install_base, args.merge_install)
        durations = DurationStore(options.build_base / DURATIONS_FILE)
        results = TestResults(options.build_base, store=switches.get("store_result", True),
                              summary=args.output == "text" and switches.get("summary", True))
        handlers = [*_handlers(args, switches, workspace.root, results), results, durations]
        try:
            tasks = plan_tests(workspace, options, durations.durations, force=args.force, use_cache=not args.no_cache)
            result = execute(tasks, handlers, workers, continue_on_error=not args.abort_on_error)
        finally:
            for handler in handlers:
                getattr(handler, "close", lambda: None)()
        durations.save()
    if result.interrupted:
        return EXIT_INTERRUPTED
    if not result.ok:
        return EXIT_FAILURE
    return EXIT_FAILURE if args.return_code_on_test_failure and results.failures else 0
