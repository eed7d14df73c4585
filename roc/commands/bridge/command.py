"""roc bridge: topics, services and actions from one ROS domain into another (like domain_bridge), from
the command line or from a domain_bridge YAML file; or one domain across networks on Zenoh; or one domain
to Foxglove in a browser. Prints what it bridges and live rates until Ctrl+C."""

from __future__ import annotations

import argparse
from pathlib import Path

from roc.commands.bridge import domains, foxglove, zenoh


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
    # -- to the browser: --foxglove and its options (roc/commands/bridge/foxglove.py) --
    foxglove.add_arguments(parser)
    # -- across networks on Zenoh: --zenoh-listen/--zenoh-connect (roc/commands/bridge/zenoh.py) --
    zenoh.add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    if args.foxglove:  # to the browser: roc/commands/bridge/foxglove.py
        return foxglove.run(args)
    if args.zenoh_listen or args.zenoh_connect or args.zenoh_config:  # roc/commands/bridge/zenoh.py
        return zenoh.run(args)
    return domains.run(args)
