"""roc bridge --foxglove: a ROS domain served to Foxglove (the browser or desktop app) over the Foxglove
WebSocket protocol; prints what it serves and live rates until Ctrl+C. The server is
roc.ros.bridges.foxglove_server; this module holds only the options and the console."""

from __future__ import annotations

import argparse

from roc.errors import UsageError
from roc.render import print_events, table_lines

# The domain bridge's options that mean nothing to --foxglove (which serves every topic of one domain).
DOMAIN_BRIDGE_OPTIONS = ("topics", "from_domain", "to_domain", "service", "action", "bidirectional", "config",
                         "all")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("to the browser (Foxglove)")
    group.add_argument("--foxglove", action="store_true",
                       help="serve every topic of the domain (see --include/--exclude; none excluded by default) "
                            "over the Foxglove WebSocket protocol, and let clients publish")
    group.add_argument("--host", default="127.0.0.1", help="with --foxglove: the address to listen on "
                                                           "(default 127.0.0.1; 0.0.0.0 for every interface)")
    group.add_argument("--port", type=int, default=8765, help="with --foxglove: the port (default 8765)")
    group.add_argument("--domain", type=int, metavar="ID",
                       help="with --foxglove or across Zenoh: the local ROS domain (default: ROS_DOMAIN_ID)")


_TEXTS = {
    "advertised": "advertised {topic} [{type}]",
    "unadvertised": "unadvertised {topic} [{type}]",
    "skipped": "skipped {topic} [{type}]: {reason}",
    "client_disconnected": "client {client} disconnected",
    "subscribed": "client {client} subscribed {topic}",
    "unsubscribed": "client {client} unsubscribed {topic}",
    "client_advertised": "client {client} publishes {topic} [{type}, {encoding}]",
    "client_unadvertised": "client {client} stopped publishing {topic}",
    "client_publish_refused": "client {client}: {topic}: refused: {reason}",
    "client_message_refused": "client {client}: {topic}: refused: {reason}",
}


def _text(event: dict) -> str:
    kind = event["event"]
    if kind == "serving":
        return (f"serving ROS domain {event['domain']} to Foxglove at {event['url']} "
                f"(subprotocols {', '.join(event['subprotocols'])})\n")
    if kind == "client_connected":
        return f"client {event['client']} connected ({event['subprotocol'] or 'no subprotocol'})\n"
    if kind == "rates":
        rows = [[topic, f"{rate:.1f} msg/s"] for topic, rate in sorted(event["rates"].items())]
        return "\n".join(table_lines(rows)) + "\n" if rows else ""
    if kind in _TEXTS:
        return _TEXTS[kind].format(**event) + "\n"
    return f"{kind}: {event.get('reason', '')}\n"


def run(args: argparse.Namespace) -> int:
    given = [name for name in DOMAIN_BRIDGE_OPTIONS if getattr(args, name, None)]
    if given:
        option = "the topic names" if given[0] == "topics" else f"--{given[0].replace('_', '-')}"
        raise UsageError(f"--foxglove serves every topic of one domain: drop {option} "
                         "(select topics with --include/--exclude, the domain with --domain)")
    if not 0 <= args.port <= 65535:
        raise UsageError(f"--port: expected 0 to 65535, got {args.port}")
    if args.domain is not None and not 0 <= args.domain <= 232:
        raise UsageError(f"--domain: expected a ROS domain id (0 to 232), got {args.domain}")
    from roc.ros.bridges.foxglove_server import FoxgloveServer

    server = FoxgloveServer(args.host, args.port, args.domain, args.include, args.exclude)
    try:
        print_events(server.run(), args.format, _text)
    finally:
        server.close()
    return 0
