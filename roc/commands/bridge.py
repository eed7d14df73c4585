"""roc bridge: topics, services and actions from one ROS domain into another (like domain_bridge), from
the command line or from a domain_bridge YAML file; prints what it bridges and live rates until Ctrl+C."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

from roc.errors import UsageError
from roc.fsutil import read_yaml
from roc.render import json_line, print_text, table_lines

QOS_KEYS = {"reliability", "durability", "history", "depth", "deadline", "lifespan", "liveliness",
            "liveliness_lease_duration"}
SUPPORTED_QOS = {"reliability", "durability", "history", "depth"}
ENTRY_KEYS = {"type", "from_domain", "to_domain", "remap", "qos", "reversed", "bidirectional"}
DOCUMENT_KEYS = {"name", "from_domain", "to_domain", "mode", "topics", "services", "actions"}
SECTIONS = {"topics": "topic", "services": "service", "actions": "action"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topics", nargs="*", metavar="TOPIC", help="topics to bridge, e.g. /chatter")
    parser.add_argument("--from-domain", type=int, metavar="ID", help="the ROS domain to read from")
    parser.add_argument("--to-domain", type=int, metavar="ID", help="the ROS domain to publish in")
    parser.add_argument("--service", action="append", default=[], metavar="NAME",
                        help="a service whose server is in --from-domain, to serve in --to-domain")
    parser.add_argument("--action", action="append", default=[], metavar="NAME",
                        help="an action whose server is in --from-domain, to serve in --to-domain")
    parser.add_argument("--bidirectional", action="store_true", help="bridge the topics both ways")
    parser.add_argument("--config", type=Path, metavar="FILE", help="a domain_bridge YAML file")
    parser.add_argument("--all", action="store_true", help="bridge every topic of --from-domain (see --include)")
    parser.add_argument("--include", action="append", default=[], metavar="REGEX",
                        help="with --all: only topics matching one of these")
    parser.add_argument("--exclude", action="append", default=[], metavar="REGEX",
                        help="with --all: never topics matching one of these (default: /rosout, /parameter_events)")
    parser.add_argument("--format", choices=("text", "json"), default="text",
                        help="json: one status object per line")


def _domain(value: Any, where: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 232:
        raise UsageError(f"{where}: expected a ROS domain id (0 to 232), got {value!r}")
    return value


def _absolute(name: str) -> str:
    return name if name.startswith("/") else f"/{name}"


def _entries(path: Path) -> tuple[dict[str, Any], list[tuple[str, str, int, Any]]]:
    """The file's top-level settings, and its (section, name, line, spec) entries in order. A section
    may name a topic twice (domain_bridge's own example does, for two destinations), so mappings are
    read from YAML's node tree rather than into dicts, which would keep only the last."""
    root = read_yaml(path, nodes=True)
    if root is None:
        raise UsageError(f"{path}: the file is empty; give 'topics:', 'services:' or 'actions:'")
    if not isinstance(root, yaml.MappingNode):
        raise UsageError(f"{path}: expected a mapping with 'topics: {{NAME: {{type: ...}}}}' as domain_bridge reads")
    settings: dict[str, Any] = {}
    entries = []
    for key_node, value_node in root.value:
        key = key_node.value
        if key not in DOCUMENT_KEYS:
            raise UsageError(f"{path}:{key_node.start_mark.line + 1}: unknown key '{key}' "
                             f"(known: {', '.join(sorted(DOCUMENT_KEYS))})")
        if key not in SECTIONS:
            settings[key] = yaml.safe_load(yaml.serialize(value_node))
            continue
        if isinstance(value_node, yaml.ScalarNode) and value_node.value in ("", "null", "~"):
            continue
        if not isinstance(value_node, yaml.MappingNode):
            raise UsageError(f"{path}:{value_node.start_mark.line + 1}: {key}: expected NAME: {{type: ...}} entries")
        for name_node, spec_node in value_node.value:
            spec = yaml.safe_load(yaml.serialize(spec_node)) or {}
            entries.append((key, str(name_node.value), name_node.start_mark.line + 1, spec))
    return settings, entries


def routes_from_config(path: Path) -> list:
    """The routes of a domain_bridge YAML file: ``from_domain``, ``to_domain`` and ``topics``,
    ``services``, ``actions``: ``{NAME: {type, from_domain, to_domain, remap, qos, reversed,
    bidirectional}}``."""
    from roc.ros.bridge import Route

    settings, entries = _entries(path)
    if settings.get("mode", "normal") != "normal":
        raise UsageError(f"{path}: mode: only 'normal' is supported (not {settings['mode']!r}); remove 'mode'")
    routes = []
    for section, name, line, spec in entries:
        where = f"{path}:{line}: {section}: {name}"
        if not isinstance(spec, dict):
            raise UsageError(f"{where}: expected a mapping such as {{type: pkg/msg/Type}}")
        unknown = set(spec) - ENTRY_KEYS
        if unknown:
            raise UsageError(f"{where}: unknown key '{sorted(unknown)[0]}' (known: {', '.join(sorted(ENTRY_KEYS))})")
        qos = spec.get("qos") or {}
        if not isinstance(qos, dict) or set(qos) - QOS_KEYS:
            raise UsageError(f"{where}: qos: use {', '.join(sorted(QOS_KEYS))}")
        if set(qos) - SUPPORTED_QOS and any(qos[key] != "auto" for key in set(qos) - SUPPORTED_QOS):
            raise UsageError(f"{where}: qos: {sorted(set(qos) - SUPPORTED_QOS)[0]}: only 'auto' is supported; "
                             f"roc sets {', '.join(sorted(SUPPORTED_QOS))}")
        domains = [_domain(spec.get(key, settings.get(key, 0)), f"{where}: {key}") for key in ("from_domain", "to_domain")]
        remap = spec.get("remap")
        route = Route(_absolute(name), *domains, spec.get("type"), remap and _absolute(remap),
                      {k: v for k, v in qos.items() if k in SUPPORTED_QOS}, SECTIONS[section])
        if spec.get("reversed"):
            route = route.swapped()
        routes.append(route)
        if spec.get("bidirectional"):
            if section != "topics":
                raise UsageError(f"{where}: bidirectional: only topics go both ways; bridge the {section[:-1]} "
                                 "again with 'reversed: true' for a server on the other side")
            routes.append(route.swapped())
    return routes


def _routes(args: argparse.Namespace) -> list:
    from roc.ros.bridge import Route

    routes = routes_from_config(args.config) if args.config else []
    named = [*args.topics, *args.service, *args.action]
    if named or args.all:
        if args.from_domain is None or args.to_domain is None:
            raise UsageError("give --from-domain and --to-domain with topics, --service, --action or --all")
        source, target = _domain(args.from_domain, "--from-domain"), _domain(args.to_domain, "--to-domain")
        for kind, names in (("topic", args.topics), ("service", args.service), ("action", args.action)):
            routes += [Route(_absolute(name), source, target, kind=kind) for name in names]
        if args.bidirectional:
            routes += [Route(_absolute(name), target, source) for name in args.topics]
    if not routes and not args.all:
        raise UsageError("nothing to bridge: name topics, --service, --action, --all, or --config FILE")
    for route in routes:
        if route.from_domain == route.to_domain and route.target == route.name:
            raise UsageError(f"{route.name}: bridging domain {route.from_domain} into itself would loop")
    return routes


def _text(event: dict[str, Any]) -> str:
    if event["event"] == "bridging":
        qos = f" ({event['reliability']}, {event['durability']})" if event["kind"] == "topic" else ""
        kind = "" if event["kind"] == "topic" else "service "
        renamed = f" as {event['target']}" if event["target"] != event["topic"] else ""
        return (f"bridging {kind}{event['topic']} [{event['type']}] domain {event['from_domain']} -> "
                f"{event['to_domain']}{renamed}{qos}\n")
    if event["event"] == "error":
        return f"error: {event['message']}\n"
    return "\n".join(table_lines([[name, f"{rate:.1f} {'calls' if name.startswith('service ') else 'msg'}/s"] for name, rate in event["rates"].items()])) + "\n"


def run(args: argparse.Namespace) -> int:
    from roc.ros.bridge import DomainBridge

    routes = _routes(args)
    exclude = args.exclude or ["^/rosout$", "^/parameter_events$"]
    bridge = DomainBridge(routes, args.include, exclude, (args.from_domain, args.to_domain) if args.all else None)
    try:
        for event in bridge.run():
            if args.format == "json":
                print_text(json_line(event))
            elif event["event"] != "rates" or event["rates"]:
                print_text(_text(event))
    finally:
        bridge.close()
    return 0
