"""roc graph check: probe a running ROS system against the expectations declared in roc.toml's
[check] table (or --file), each a task of roc's engine; exit 0 only when every probe passes."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from roc.cli.options import add_discovery_arguments
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, UsageError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--file", type=Path, metavar="FILE",
                        help="a TOML file with a [check] table (default: roc.toml here or above)")
    parser.add_argument("--output", choices=("text", "json"), default="text",
                        help="json: one JSON event per line on stdout (with each probe's ProbeResult)")
    parser.add_argument("--junit-xml", type=Path, metavar="FILE", help="also write a JUnit XML report")
    parser.add_argument("--parallel-workers", type=int, default=0, metavar="NUMBER",
                        help="probes run at once, 0 for all (default)")
    parser.add_argument("--watch", action="store_true", help="probe again and again until Ctrl+C")
    parser.add_argument("--interval", type=float, default=10.0, metavar="SECONDS",
                        help="with --watch: seconds from the start of one round to the next (default: 10)")
    parser.add_argument("--prometheus", type=int, metavar="PORT",
                        help="with --watch: serve the results as Prometheus metrics on http://127.0.0.1:PORT/metrics")
    parser.add_argument("--prometheus-address", default="127.0.0.1", metavar="ADDRESS",
                        help="the address to serve the metrics on (default: 127.0.0.1; 0.0.0.0 for every interface)")
    add_discovery_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.check.expectations import find_check_file, load_checks
    from roc.check.probes import KIND, probe_console, probe_task
    from roc.engine.executor import execute
    from roc.handlers.logs import JsonEventsHandler
    from roc.ros.client import Session

    if args.parallel_workers < 0:
        raise UsageError("--parallel-workers must be 0 (no limit) or more")
    if (args.prometheus is not None or args.interval != 10.0) and not args.watch:
        raise UsageError("--prometheus and --interval go with --watch")
    if args.interval <= 0:
        raise UsageError(f"--interval: must be above 0 seconds, got {args.interval:g}")
    checks = load_checks(args.file if args.file else find_check_file(Path.cwd()))
    if not checks.expectations:
        raise UsageError(f"{checks.path}: the [check] table expects nothing; add nodes or [[check.topic]] tables")

    def handlers() -> list:
        """Each round's handlers (a console prints one summary per round)."""
        chosen: list = [*lasting]
        if args.output == "json":
            chosen.append(JsonEventsHandler(sys.stdout))
        else:
            chosen += probe_console(sys.stdout)
        if args.junit_xml:
            from roc.handlers.junit import JUnitReport

            chosen.append(JUnitReport(args.junit_xml, "roc graph check"))
        return chosen

    lasting: list = []
    metrics = None
    if args.prometheus is not None:
        from roc.handlers.metrics import PrometheusMetrics

        metrics = PrometheusMetrics()
        try:
            metrics.serve(args.prometheus, args.prometheus_address)
        except OSError as error:
            raise UsageError(f"--prometheus {args.prometheus}: cannot serve on {args.prometheus_address}: "
                             f"{error.strerror}") from None
        lasting.append(metrics)
    session = Session(use_daemon=not args.no_daemon, spin_time=args.spin_time)
    try:
        while True:
            started = time.monotonic()
            tasks = [probe_task(e, session, checks.timeout, checks.rate_window) for e in checks.expectations]
            result = execute(tasks, handlers(), args.parallel_workers, continue_on_error=True, kind=KIND)
            if metrics is not None:
                metrics.rounds.inc()
            if result.interrupted:
                return EXIT_INTERRUPTED
            if not args.watch:
                return 0 if result.ok else EXIT_FAILURE
            try:
                time.sleep(max(0.0, started + args.interval - time.monotonic()))
            except KeyboardInterrupt:
                return EXIT_INTERRUPTED
    finally:
        session.close()
        if metrics is not None:
            metrics.close()
