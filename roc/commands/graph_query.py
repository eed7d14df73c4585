"""What the graph verbs share: the query honouring ``--no-daemon``/``--spin-time``, the list and find
verbs' options and output (``-t``, ``-c``, hidden names), and the type verbs' lookup by name.

The text is ros2's for every verb; the noun (topic, service, action, node) only changes option names,
help texts and the "Unknown ..." message.
"""

from __future__ import annotations

import argparse
from typing import Any

from roc.cli.options import add_graph_arguments
from roc.errors import RocError
from roc.render import render
from roc.ros.client import query
from roc.ros.present import is_hidden
from roc.ros.protocol import DEFAULT_SPIN_TIME


def ask(args: argparse.Namespace, method: str, params: dict[str, Any] | None = None) -> Any:
    """A graph request, through the daemon unless ``--no-daemon``."""
    return query(method, params, use_daemon=not args.no_daemon, spin_time=args.spin_time)


# A warm daemon has discovered the graph; it waits this long for the publishers of a topic it does not
# know yet (one that has only just started: a new participant announces itself at once), then answers
# as ros2 does for an unknown topic, which ros2's own tests expect within 2 s.
DAEMON_PUBLISHER_WAIT = 1.0


def publisher_wait(args: argparse.Namespace) -> float:
    """How long a stream waits for a topic's publishers to be discovered: ``--spin-time`` when given; else
    a fresh participant (``--no-daemon``) waits the discovery period and the warm daemon
    DAEMON_PUBLISHER_WAIT. A topic the graph already knows costs no wait."""
    if args.spin_time is not None:
        return args.spin_time
    return DEFAULT_SPIN_TIME if args.no_daemon else DAEMON_PUBLISHER_WAIT


def snapshot(args: argparse.Namespace, kind: str) -> list[dict[str, Any]]:
    """The graph's ``topics``, ``services``, ``actions`` or ``nodes``."""
    return ask(args, "snapshot")[kind]


def add_count_argument(parser: argparse.ArgumentParser, plural: str, option: str | None = None) -> None:
    parser.add_argument("-c", option or f"--count-{plural}", dest="count", action="store_true",
                        help=f"print only the number of {plural}")


def add_hidden_argument(parser: argparse.ArgumentParser, plural: str) -> None:
    parser.add_argument(f"--include-hidden-{plural}", dest="include_hidden", action="store_true",
                        help=f"include hidden {plural} too")


def add_list_arguments(parser: argparse.ArgumentParser, noun: str, plural: str, hidden: bool = True) -> None:
    """``-t``, ``-c`` and (``hidden``) ``--include-hidden-PLURAL``, as ros2's ``NOUN list``."""
    parser.add_argument("-t", "--show-types", action="store_true", help=f"show each {noun}'s type")
    add_count_argument(parser, plural)
    if hidden:
        add_hidden_argument(parser, plural)
    add_graph_arguments(parser)


def add_find_arguments(parser: argparse.ArgumentParser, noun: str, plural: str, example: str) -> None:
    """``TYPE``, ``-c`` and ``--include-hidden-PLURAL``, as ros2's ``NOUN find``."""
    parser.add_argument(f"{noun}_type", help=f"type of the {noun}, e.g. {example}")
    add_count_argument(parser, plural)
    add_hidden_argument(parser, plural)
    add_graph_arguments(parser)


def visible(entries: list[dict[str, Any]], args: argparse.Namespace) -> list[dict[str, Any]]:
    """Without ``--include-hidden-...`` (or for verbs that have none), the entries with no hidden name."""
    if getattr(args, "include_hidden", True):
        return entries
    return [e for e in entries if not is_hidden(e["name"])]


def typed_name(entry: dict[str, Any]) -> str:
    return f"{entry['name']} [{', '.join(entry['types'])}]"


def render_listing(args: argparse.Namespace, data: list[Any], lines: list[str]) -> None:
    """A listing, or with ``-c`` only its length."""
    if args.count:
        render({"count": len(data)}, args.format, [str(len(data))])
    else:
        render(data, args.format, lines)


def run_list(args: argparse.Namespace, kind: str) -> int:
    """``topic|service|action list`` without verbose output: names, ``-t`` with types, or ``-c``."""
    entries = visible(snapshot(args, kind), args)
    render_listing(args, entries, [typed_name(e) if args.show_types else e["name"] for e in entries])
    return 0


def run_find(args: argparse.Namespace, kind: str, type_name: str) -> int:
    """``topic|service find TYPE``: the names of that type (JSON: a list of names)."""
    names = [e["name"] for e in visible(snapshot(args, kind), args) if type_name in e["types"]]
    render_listing(args, names, names)
    return 0


def add_type_arguments(parser: argparse.ArgumentParser, noun: str, plural: str, example: str,
                       hidden: bool = True) -> None:
    """``NAME`` and (``hidden``) ``--include-hidden-PLURAL``, as ros2's ``NOUN type``."""
    parser.add_argument(f"{noun}_name", help=f"name of the {noun}, e.g. {example}")
    if hidden:
        add_hidden_argument(parser, plural)
    add_graph_arguments(parser)


def run_type(args: argparse.Namespace, kind: str, noun: str, name: str) -> int:
    """``topic|service|action type NAME``: its types, one a line; ros2's "Unknown NOUN 'NAME'" if none
    (and for a hidden name without ``--include-hidden-...``, as ros2)."""
    entries = snapshot(args, kind)
    types = next((e["types"] for e in visible(entries, args) if e["name"] == name), None)
    if types is None:
        hidden = any(e["name"] == name for e in entries)
        hint = f" (a hidden {noun}: add --include-hidden-{kind})" if hidden else ""
        raise RocError(f"Unknown {noun} '{name}'{hint}")
    render({"name": name, "types": types}, args.format, types)
    return 0
