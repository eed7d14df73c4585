"""Event handlers: the console, log files, stored results and JSON events for CI.

``EVENT_HANDLERS`` is the registry of colcon's ``--event-handlers`` names roc has (enabled unless
the default says otherwise), ``output_handlers`` builds the handlers of a run from the switches; every
verb that runs tasks (``work build``, ``work test``) goes through it.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from roc.errors import UsageError

# name -> (enabled by default, what it does)
EVENT_HANDLERS: dict[str, tuple[bool, str]] = {
    "console_start_end": (True, "a line when each task starts and ends"),
    "console_stderr": (True, "each task's stderr as one block when it ends"),
    "console_direct": (False, "every task's output as it comes"),
    "console_cohesion": (False, "each task's whole output as one block when it ends"),
    "summary": (True, "the summary at the end"),
    "status": (True, "the live status line on a terminal"),
    "log": (True, "logs in <log-base>/<verb>_<time>/"),
    "event_log": (True, "every event in the log directory's events.log (JSON lines)"),
    "log_command": (True, "each command a task runs in its command.log"),
    "store_result": (True, "each package's result in <build-base>/<pkg>/colcon_<verb>.rc"),
}
# colcon's handlers roc does not have: accepted when disabled.
NOT_SUPPORTED_HANDLERS = ("compile_commands", "desktop_notification", "terminal_title", "console_package_list",
                          "parallel_status")


def add_event_handlers_argument(parser: argparse.ArgumentParser) -> None:
    action = parser.add_argument(
        "--event-handlers", nargs="*", metavar="NAME+/-", default=[],
        help="enable (+) or disable (-) output: " + ", ".join(EVENT_HANDLERS))
    # the words roc/commands/completion.py offers for it (not argparse choices: several may be given)
    words = [f"{name}{sign}" for name in sorted(EVENT_HANDLERS) for sign in "+-"]
    action.completion = words  # type: ignore[attr-defined]


def handler_switches(values: list[str]) -> dict[str, bool]:
    """Each handler on or off, from ``--event-handlers`` values like ``console_direct+ status-``."""
    switches = {name: default for name, (default, _) in EVENT_HANDLERS.items()}
    for value in values:
        name, sign = value[:-1], value[-1:]
        if sign not in "+-" or not name:
            raise UsageError(f"--event-handlers: '{value}' must be a name followed by + or -")
        if name in NOT_SUPPORTED_HANDLERS and sign == "+":
            raise UsageError(f"--event-handlers: roc does not support '{name}' yet")
        if name not in EVENT_HANDLERS and name not in NOT_SUPPORTED_HANDLERS:
            raise UsageError(f"--event-handlers: unknown handler '{name}'; known: {', '.join(sorted(EVENT_HANDLERS))}")
        switches[name] = sign == "+"
    return switches


def output_handlers(args: argparse.Namespace, switches: dict[str, bool], root: Path, build_base: Path,
                    verb: str = "build", console: bool = True, **console_options) -> list:
    """Where a run's events go: logs, stored results, and the console (or JSON events on stdout;
    neither without ``console``: roc tui shows the run). ``verb`` is also the run's own kind of task
    (``build``, ``test``)."""
    from roc.handlers.console import ConsoleHandler
    from roc.handlers.logs import (
        JsonEventsHandler,
        LogHandler,
        ResultStore,
        new_log_directory,
    )

    handlers: list = []
    log_dir = None
    if args.log_base != os.devnull and switches["log"]:
        log_dir = new_log_directory((root / args.log_base).absolute(), verb)
        handlers.append(LogHandler(log_dir, events=switches["event_log"], commands=switches["log_command"],
                                   kind=verb))
    if switches["store_result"]:
        handlers.append(ResultStore(build_base, kind=verb))
    if not console:
        return handlers
    if args.output == "json":
        handlers.append(JsonEventsHandler(sys.stdout))
        return handlers
    status = None
    if switches["status"] and sys.stdout.isatty() and not os.environ.get("NO_COLOR"):
        from roc.handlers.status import StatusLine

        status = StatusLine(kind=verb)
    handlers.append(ConsoleHandler(
        start_end=switches["console_start_end"], stderr=switches["console_stderr"], summary=switches["summary"],
        direct=switches["console_direct"], cohesion=switches["console_cohesion"],
        log_path=str(log_dir) if log_dir else None, status=status, kind=verb, **console_options,
    ))
    return handlers
