"""roc doctor: check what most often keeps ROS 2 nodes from talking (like ros2 doctor): the
environment (distribution, middleware, domain, discovery range, overlays that shadow each other), the
network and multicast, and the live graph (nodes sharing a name, QoS-incompatible endpoints, topics
published but not subscribed or the reverse). Exit 1 when a check fails."""

from __future__ import annotations

import argparse
import os
from typing import Any

from roc.cli.options import add_graph_arguments
from roc.doctor import environment, live_graph, network
from roc.doctor.findings import LEVELS, Finding, summary
from roc.errors import RocError
from roc.render import render
from roc.ros.protocol import discovery_range

REPORT_CATEGORIES = {"environment": ("PLATFORM INFORMATION", "ROS 2 INFORMATION", "ROS ENVIRONMENT", "RMW MIDDLEWARE"),
                     "network": ("NETWORK CONFIGURATION",), "graph": ("TOPIC LIST", "QOS COMPATIBILITY LIST")}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    reports = parser.add_mutually_exclusive_group()
    reports.add_argument("--report", "-r", action="store_true", help="print every report (and no checks)")
    reports.add_argument("--report-failed", "-rf", action="store_true", help="print the reports of failed checks")
    parser.add_argument("--exclude-packages", "-ep", action="store_true",
                        help="accepted for ros2's sake: roc does not compare package versions with rosdistro")
    parser.add_argument("--include-warnings", "-iw", action="store_true", help="count warnings as failed checks")
    parser.add_argument("--fix", action="store_true",
                        help="first apply the repairs that are safe (the CMake files of ROS 2's PyPI wheels in "
                             "roc's environment) and say what changed")
    add_graph_arguments(parser)


def _graph(args: argparse.Namespace) -> tuple[list[Finding], dict[str, Any] | None]:
    from roc.distribution import mix
    from roc.ros.client import Session

    if mix():  # rclpy would crash on two distributions' libraries: the distribution check says which
        return [Finding(live_graph.CATEGORY, "graph", "error", "not checked: two ROS 2 distributions are sourced",
                        "see the distribution check above")], None
    try:
        session = Session(use_daemon=not args.no_daemon, spin_time=args.spin_time)
    except RocError as error:
        return [Finding(live_graph.CATEGORY, "graph", "error", f"cannot reach the graph: {error}",
                        "run 'roc daemon stop' and retry, or use --no-daemon")], None
    try:
        return live_graph.checks(lambda method, params: session.query(method, params))
    finally:
        session.close()


def report_lines(name: str, items: list[tuple[str, str]]) -> list[str]:
    """A report as ros2 doctor prints it: its name, then ``item: value`` lines padded alike."""
    width = max([8] + [len(item) + 4 for item, _ in items if len(item) >= 8])
    return ["", f"   {name}", *(f"{item:{width}}: {value}" for item, value in items)]


def _finding_lines(findings: list[Finding]) -> list[str]:
    """The findings by category, one a line (``level  check: message``), each fix on the line after."""
    lines = []
    width = max(map(len, LEVELS))
    for category in dict.fromkeys(f.category for f in findings):
        lines.append(f"{category}:")
        for finding in (f for f in findings if f.category == category):
            lines.append(f"  {finding.level:{width}}  {finding.check}: {finding.message}")
            if finding.fix:
                lines.append(f"  {'':{width}}  fix: {finding.fix}")
    return lines


def _fix() -> list[str]:
    """Apply the safe repairs; one line per changed file."""
    from roc.doctor import wheel_repairs
    from roc.environment import own_prefix

    prefix = own_prefix()
    repairs = wheel_repairs.planned(prefix, wheel_repairs.this_interpreter()) if prefix else []
    wheel_repairs.apply(repairs)
    return [f"fixed {repair.path}: {repair.why}" for repair in repairs] or ["nothing to fix"]


def run(args: argparse.Namespace) -> int:
    fixed = _fix() if args.fix else []
    findings = environment.checks()
    findings += network.checks(discovery_range(os.environ))
    graph_findings, asked = _graph(args)
    findings += graph_findings
    result = summary(findings, args.include_warnings)
    reports: dict[str, list[tuple[str, str]]] = {}
    if args.report or args.report_failed:
        reports = {**environment.reports(), "NETWORK CONFIGURATION": network.report(),
                   **(live_graph.reports(asked) if asked else {})}
        if args.report_failed:
            wanted = {name for category in result["failed_categories"] for name in REPORT_CATEGORIES[category]}
            reports = {name: items for name, items in reports.items() if name in wanted}
    if args.report:
        lines = [line for name, items in reports.items() for line in report_lines(name, items)]
    else:
        lines = [*fixed, *([""] if fixed else []), *_finding_lines(findings), ""]
        if result["failed"]:
            lines += [f"{result['failed']}/{result['checks']} check(s) failed", "",
                      "Failed modules: " + " ".join(result["failed_categories"])]
        else:
            lines.append(f"All {result['checks']} checks passed")
        lines += [line for name, items in reports.items() for line in report_lines(name, items)]
    data = {**({"fixed": fixed} if args.fix else {}), "findings": [f.as_dict() for f in findings], **result,
            **({"reports": {name: [{"item": k, "value": v} for k, v in items] for name, items in reports.items()}}
               if reports else {})}
    render(data, args.format, lines)
    return 1 if result["failed"] else 0
