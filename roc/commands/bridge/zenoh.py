"""roc bridge --zenoh-listen/--zenoh-connect: the selected topics, services and actions carried between
the local ROS domain and the far side's ``roc bridge`` over Zenoh, both ways; prints what it carries and
live rates until Ctrl+C. The link is roc.ros.bridges.zenoh_link; this module holds only the options and the
console."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from roc.commands.bridge.domains import absolute, domain_id, status_text
from roc.errors import UsageError
from roc.render import print_events


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The Zenoh options (``--domain`` is shared with --foxglove, which defines it)."""
    group = parser.add_argument_group("across networks on Zenoh (run one roc bridge on each side)")
    group.add_argument("--zenoh-listen", action="append", default=[], metavar="ENDPOINT",
                       help="accept Zenoh peers on this endpoint, e.g. tcp/0.0.0.0:7447")
    group.add_argument("--zenoh-connect", action="append", default=[], metavar="ENDPOINT",
                       help="connect to a Zenoh peer, e.g. tcp/robot.local:7447 (retried until it answers)")
    group.add_argument("--zenoh-config", type=Path, metavar="FILE",
                       help="a Zenoh JSON5 configuration (e.g. for TLS); the endpoints given are added to it")


def _text(event: dict[str, Any]) -> str:
    if event["event"] == "bridging":
        way = (f"domain {event['domain']} -> zenoh" if event["direction"] == "out"
               else f"zenoh -> domain {event['domain']}")
        qos = f" ({event['reliability']}, {event['durability']})" if event["kind"] == "topic" else ""
        kind = "" if event["kind"] == "topic" else "service "
        return f"bridging {kind}{event['topic']} [{event['type']}] {way}{qos}\n"
    if event["event"] == "session":
        return f"zenoh session {event['zid']} on domain {event['domain']}\n"
    if event["event"] == "peer":
        return f"zenoh peer {event['zid']} {'connected' if event['connected'] else 'gone'}\n"
    return status_text(event)


def run(args: argparse.Namespace) -> int:
    """Carry the selected topics, services and actions between the local domain and the Zenoh peers."""
    from roc.ros.bridges.zenoh_link import ZenohLink, zenoh_config

    if args.from_domain is not None or args.to_domain is not None or args.config:
        raise UsageError("--from-domain, --to-domain and --config bridge domains; "
                         "across Zenoh give --domain and topics, --all, --service or --action")
    if not args.topics and not args.all and not args.service and not args.action:
        raise UsageError("nothing to bridge: name topics, --all, --service or --action")
    domain = args.domain if args.domain is not None else os.environ.get("ROS_DOMAIN_ID") or 0
    try:
        domain = domain_id(int(domain), "--domain")
    except ValueError:
        raise UsageError(f"ROS_DOMAIN_ID: expected a ROS domain id (0 to 232), got {domain!r}") from None
    config = zenoh_config(args.zenoh_listen, args.zenoh_connect, args.zenoh_config)
    exclude = args.exclude or ["^/rosout$", "^/parameter_events$"]
    link = ZenohLink(domain, [absolute(t) for t in args.topics], args.include, exclude, args.all, config,
                     [absolute(s) for s in args.service], [absolute(a) for a in args.action])
    try:
        print_events(link.run(), args.format, _text)
    finally:
        link.close()
    return 0
