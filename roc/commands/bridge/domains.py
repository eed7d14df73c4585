"""The domain bridge of ``roc bridge``: routes from the command line or a domain_bridge YAML file, and
the text of its status events (the Zenoh and Foxglove modes print theirs through it too)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

from roc.errors import UsageError
from roc.fsutil import read_yaml
from roc.render import print_events, table_lines

QOS_KEYS = {"reliability", "durability", "history", "depth", "deadline", "lifespan", "liveliness",
            "liveliness_lease_duration"}
SUPPORTED_QOS = {"reliability", "durability", "history", "depth"}
ENTRY_KEYS = {"type", "from_domain", "to_domain", "remap", "qos", "reversed", "bidirectional"}
DOCUMENT_KEYS = {"name", "from_domain", "to_domain", "mode", "topics", "services", "actions"}
SECTIONS = {"topics": "topic", "services": "service", "actions": "action"}


def domain_id(value: Any, where: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 232:
        raise UsageError(f"{where}: expected a ROS domain id (0 to 232), got {value!r}")
    return value


def absolute(name: str) -> str:
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
    from roc.ros.bridges.domains import Route

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
            raise UsageError(f"{where}: unknown key '{min(unknown)}' (known: {', '.join(sorted(ENTRY_KEYS))})")
        qos = spec.get("qos") or {}
        if not isinstance(qos, dict) or set(qos) - QOS_KEYS:
            raise UsageError(f"{where}: qos: use {', '.join(sorted(QOS_KEYS))}")
        if set(qos) - SUPPORTED_QOS and any(qos[key] != "auto" for key in set(qos) - SUPPORTED_QOS):
            raise UsageError(f"{where}: qos: {min(set(qos) - SUPPORTED_QOS)}: only 'auto' is supported; "
                             f"roc sets {', '.join(sorted(SUPPORTED_QOS))}")
        source, target = (domain_id(spec.get(key, settings.get(key, 0)), f"{where}: {key}")
                          for key in ("from_domain", "to_domain"))
        remap = spec.get("remap")
        route = Route(absolute(name), source, target, spec.get("type"), remap and absolute(remap),
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
    from roc.ros.bridges.domains import Route

    routes = routes_from_config(args.config) if args.config else []
    named = [*args.topics, *args.service, *args.action]
    if named or args.all:
        if args.from_domain is None or args.to_domain is None:
            raise UsageError("give --from-domain and --to-domain with topics, --service, --action or --all")
        source, target = domain_id(args.from_domain, "--from-domain"), domain_id(args.to_domain, "--to-domain")
        for kind, names in (("topic", args.topics), ("service", args.service), ("action", args.action)):
            routes += [Route(absolute(name), source, target, kind=kind) for name in names]
        if args.bidirectional:
            routes += [Route(absolute(name), target, source) for name in args.topics]
    if not routes and not args.all:
        raise UsageError("nothing to bridge: name topics, --service, --action, --all, or --config FILE")
    for route in routes:
        if route.from_domain == route.to_domain and route.target == route.name:
            raise UsageError(f"{route.name}: bridging domain {route.from_domain} into itself would loop")
    return routes


def status_text(event: dict[str, Any]) -> str:
    if event["event"] == "bridging":
        qos = f" ({event['reliability']}, {event['durability']})" if event["kind"] == "topic" else ""
        kind = "" if event["kind"] == "topic" else "service "
        renamed = f" as {event['target']}" if event["target"] != event["topic"] else ""
        return (f"bridging {kind}{event['topic']} [{event['type']}] domain {event['from_domain']} -> "
                f"{event['to_domain']}{renamed}{qos}\n")
    if event["event"] == "error":
        return f"error: {event['message']}\n"
    rows = [[name, f"{rate:.1f} {'calls' if name.startswith('service ') else 'msg'}/s"]
            for name, rate in event["rates"].items()]
    return "\n".join(table_lines(rows)) + "\n" if rows else ""




def run(args: argparse.Namespace) -> int:
    """Bridge the routes of the command line and ``--config`` until Ctrl+C."""
    from roc.ros.bridges.domains import DomainBridge

    routes = _routes(args)
    exclude = args.exclude or ["^/rosout$", "^/parameter_events$"]
    bridge = DomainBridge(routes, args.include, exclude, (args.from_domain, args.to_domain) if args.all else None)
    try:
        print_events(bridge.run(), args.format, status_text)
    finally:
        bridge.close()
    return 0
