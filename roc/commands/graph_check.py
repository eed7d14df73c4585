"""roc graph check: probe a running ROS system against the expectations declared in roc.toml's
[check] table (or --file), each a task of roc's engine; exit 0 only when every probe passes."""

from __future__ import annotations

import argparse
import sys
from functools import partial
from pathlib import Path

from roc.cli.options import add_discovery_arguments
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, UsageError

KIND = "probe"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--file", type=Path, metavar="FILE",
                        help="a TOML file with a [check] table (default: roc.toml here or above)")
    parser.add_argument("--output", choices=("text", "json"), default="text",
                        help="json: one JSON event per line on stdout (with each probe's ProbeResult)")
    parser.add_argument("--junit-xml", type=Path, metavar="FILE", help="also write a JUnit XML report")
    parser.add_argument("--parallel-workers", type=int, default=0, metavar="NUMBER",
                        help="probes run at once, 0 for all (default)")
    add_discovery_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.check.expectations import find_check_file, load_checks
    from roc.check.probes import probe
    from roc.engine.events import ProbeResult
    from roc.engine.executor import execute
    from roc.engine.process import TaskError
    from roc.engine.ready import Task
    from roc.handlers.console import ConsoleHandler
    from roc.handlers.logs import JsonEventsHandler
    from roc.ros.client import Session

    if args.parallel_workers < 0:
        raise UsageError("--parallel-workers must be 0 (no limit) or more")
    checks = load_checks(args.file if args.file else find_check_file(Path.cwd()))
    if not checks.expectations:
        raise UsageError(f"{checks.path}: the [check] table expects nothing; add nodes or [[check.topic]] tables")

    def run_probe(expectation, session, context) -> None:
        verdict = probe(expectation, session, checks.timeout, checks.rate_window)
        context.emit(ProbeResult(expectation.label, KIND, status=verdict.status, message=verdict.message,
                                 expected=expectation.values, measured=verdict.measured))
        if verdict.status != "pass":
            raise TaskError(f"{verdict.status}: {verdict.message} ({expectation.where})")

    found: dict[str, str] = {}

    def remember(event) -> None:
        if isinstance(event, ProbeResult):
            found[event.key] = event.message

    handlers: list = [remember]
    if args.output == "json":
        handlers.append(JsonEventsHandler(sys.stdout))
    else:
        handlers.append(ConsoleHandler(sys.stdout, kind=KIND, noun="probe", cached_label="",
                                       finished_note=lambda key: f"  {found.get(key, '')}"))
    if args.junit_xml:
        from roc.handlers.junit import JUnitReport

        handlers.append(JUnitReport(args.junit_xml, "roc graph check"))
    session = Session(use_daemon=not args.no_daemon, spin_time=args.spin_time)
    try:
        tasks = [Task(name=e.label, dependencies=set(), action=partial(run_probe, e, session), kind=KIND)
                 for e in checks.expectations]
        result = execute(tasks, handlers, args.parallel_workers, continue_on_error=True)
    finally:
        session.close()
    if result.interrupted:
        return EXIT_INTERRUPTED
    return 0 if result.ok else EXIT_FAILURE
