"""roc bridge: topics from one ROS domain into another (like domain_bridge), from the command line or
from a domain_bridge YAML file; prints what it bridges and live rates until Ctrl+C."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from roc.errors import UsageError
from roc.fsutil import read_yaml
from roc.render import json_line, print_text, table_lines

QOS_KEYS = {"reliability", "durability", "history", "depth"}
TOPIC_KEYS = {"type", "from_domain", "to_domain", "remap", "qos", "reversed", "bidirectional"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("topics", nargs="*", metavar="TOPIC", help="topics to bridge, e.g. /chatter")
    parser.add_argument("--from-domain", type=int, metavar="ID", help="the ROS domain to read from")
    parser.add_argument("--to-domain", type=int, metavar="ID", help="the ROS domain to publish in")
    parser.add_argument("--config", type=Path, metavar="FILE", help="a domain_bridge YAML file")
    parser.add_argument("--all", action="store_true", help="bridge every topic of --from-domain (see --include)")
    parser.add_argument("--include", action="append", default=[], metavar="REGEX",
                        help="with --all: only topics matching one of these")
    parser.add_argument("--exclude", action="append", default=[], metavar="REGEX",
                        help="with --all: never topics matching one of these (default: /rosout, /parameter_events)")
    parser.add_argument("--format", choices=("text", "json"), default="text",
                        help="json: one status object per line")
    add_zenoh_arguments(parser)


def _domain(value: Any, where: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 232:
        raise UsageError(f"{where}: expected a ROS domain id (0 to 232), got {value!r}")
    return value


def routes_from_config(path: Path):
    """The routes of a domain_bridge YAML file (``from_domain``, ``to_domain``, ``topics: {NAME: {type,
    from_domain, to_domain, remap, qos}}``)."""
    from roc.ros.bridge import Route

    document = read_yaml(path)
    if not isinstance(document, dict) or not isinstance(document.get("topics", {}), dict):
        raise UsageError(f"{path}: expected a mapping with 'topics: {{NAME: {{type: ...}}}}' as domain_bridge reads")
    if document.get("services") or document.get("actions"):
        raise UsageError(f"{path}: bridging services and actions is not supported yet; remove 'services'/'actions'")
    routes = []
    for name, spec in document.get("topics", {}).items():
        spec = spec or {}
        where = f"{path}: topics: {name}"
        unknown = set(spec) - TOPIC_KEYS
        if unknown:
            raise UsageError(f"{where}: unknown key '{sorted(unknown)[0]}' (known: {', '.join(sorted(TOPIC_KEYS))})")
        if spec.get("reversed") or spec.get("bidirectional"):
            raise UsageError(f"{where}: 'reversed' and 'bidirectional' are not supported yet (roc cannot yet keep "
                             "a two-way bridge from echoing its own messages)")
        qos = spec.get("qos") or {}
        if not isinstance(qos, dict) or set(qos) - QOS_KEYS:
            raise UsageError(f"{where}: qos: use {', '.join(sorted(QOS_KEYS))}")
        topic = name if name.startswith("/") else f"/{name}"
        remap = spec.get("remap")
        routes.append(Route(topic, _domain(spec.get("from_domain", document.get("from_domain", 0)), f"{where}: from_domain"),
                            _domain(spec.get("to_domain", document.get("to_domain", 0)), f"{where}: to_domain"),
                            spec.get("type"), remap if remap is None or remap.startswith("/") else f"/{remap}", qos))
    return routes


def run(args: argparse.Namespace) -> int:
    if args.zenoh_listen or args.zenoh_connect or args.zenoh_config:
        return run_zenoh(args)
    from roc.ros.bridge import DomainBridge, Route

    routes = routes_from_config(args.config) if args.config else []
    if args.topics or args.all:
        if args.from_domain is None or args.to_domain is None:
            raise UsageError("give --from-domain and --to-domain with topics or --all")
        _domain(args.from_domain, "--from-domain"), _domain(args.to_domain, "--to-domain")
        routes += [Route(t if t.startswith("/") else f"/{t}", args.from_domain, args.to_domain) for t in args.topics]
    if not routes and not args.all:
        raise UsageError("nothing to bridge: name topics, or --all, or --config FILE")
    for route in routes:
        if route.from_domain == route.to_domain and route.target == route.topic:
            raise UsageError(f"{route.topic}: bridging domain {route.from_domain} into itself would loop")
    exclude = args.exclude or ["^/rosout$", "^/parameter_events$"]
    bridge = DomainBridge(routes, args.include, exclude, (args.from_domain, args.to_domain) if args.all else None)
    try:
        for event in bridge.run():
            if args.format == "json":
                print_text(json_line(event))
            elif event["event"] == "bridging":
                print_text(f"bridging {event['topic']} [{event['type']}] domain {event['from_domain']} -> "
                           f"{event['to_domain']}{' as ' + event['target'] if event['target'] != event['topic'] else ''}"
                           f" ({event['reliability']}, {event['durability']})\n")
            elif event["rates"]:
                print_text("\n".join(table_lines([[topic, f"{rate:.1f} msg/s"] for topic, rate in event["rates"].items()]))
                           + "\n")
    finally:
        bridge.close()
    return 0


# ---- across networks on Zenoh (roc.ros.zenoh_link) -------------------------------------------------

def add_zenoh_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("across networks on Zenoh (run one roc bridge on each side)")
    group.add_argument("--zenoh-listen", action="append", default=[], metavar="ENDPOINT",
                       help="accept Zenoh peers on this endpoint, e.g. tcp/0.0.0.0:7447")
    group.add_argument("--zenoh-connect", action="append", default=[], metavar="ENDPOINT",
                       help="connect to a Zenoh peer, e.g. tcp/robot.local:7447 (retried until it answers)")
    group.add_argument("--zenoh-config", type=Path, metavar="FILE",
                       help="a Zenoh JSON5 configuration (e.g. for TLS); the endpoints given are added to it")
    group.add_argument("--domain", type=int, metavar="ID",
                       help="the local ROS domain to carry topics from and to (default: ROS_DOMAIN_ID, else 0)")


def run_zenoh(args: argparse.Namespace) -> int:
    """Carry the selected topics between the local domain and the Zenoh peers, both ways, until Ctrl+C."""
    import os
    import sys

    from roc.ros.zenoh_link import ZenohLink, zenoh_config

    if args.from_domain is not None or args.to_domain is not None or args.config:
        raise UsageError("--from-domain, --to-domain and --config bridge domains; across Zenoh give --domain")
    if not args.topics and not args.all:
        raise UsageError("nothing to bridge: name topics, or --all")
    if not args.zenoh_listen and not args.zenoh_connect and args.zenoh_config is None:
        raise UsageError("give --zenoh-listen ENDPOINT or --zenoh-connect ENDPOINT")
    domain = args.domain if args.domain is not None else os.environ.get("ROS_DOMAIN_ID") or 0
    try:
        domain = _domain(int(domain), "--domain")
    except ValueError:
        raise UsageError(f"ROS_DOMAIN_ID: expected a ROS domain id (0 to 232), got {domain!r}") from None
    config = zenoh_config(args.zenoh_listen, args.zenoh_connect, args.zenoh_config)
    exclude = args.exclude or ["^/rosout$", "^/parameter_events$"]
    link = ZenohLink(domain, [t if t.startswith("/") else f"/{t}" for t in args.topics], args.include, exclude, args.all, config)
    try:
        for event in link.run():
            if args.format == "json":
                print_text(json_line(event))
            elif event["event"] == "bridging":
                way = (f"domain {event['domain']} -> zenoh" if event["direction"] == "out"
                       else f"zenoh -> domain {event['domain']}")
                print_text(f"bridging {event['topic']} [{event['type']}] {way} "
                           f"({event['reliability']}, {event['durability']})\n")
            elif event["event"] == "session":
                print_text(f"zenoh session {event['zid']} on domain {event['domain']}\n")
            elif event["event"] == "peer":
                print_text(f"zenoh peer {event['zid']} {'connected' if event['connected'] else 'gone'}\n")
            elif event["event"] == "error":
                print_text(f"roc: error: {event['message']}\n", sys.stderr)
            elif event["rates"]:
                print_text("\n".join(table_lines([[topic, f"{rate:.1f} msg/s"]
                                                  for topic, rate in event["rates"].items()])) + "\n")
    finally:
        link.close()
    return 0
