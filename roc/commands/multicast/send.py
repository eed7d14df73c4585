"""roc multicast send: send one UDP multicast datagram (like ros2 multicast send); run roc multicast
receive on another host to see whether multicast gets from one to the other."""

from __future__ import annotations

import argparse

from roc.commands.multicast.receive import add_multicast_arguments
from roc.doctor.network import send
from roc.errors import RocError
from roc.render import print_text, render

DATA = b"Hello World!"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_multicast_arguments(parser)
    parser.add_argument("--ttl", type=int, help="the multicast TTL (hops; default: the system's, 1)")


def run(args: argparse.Namespace) -> int:
    if args.format == "text":
        print_text("Sending one UDP multicast datagram...\n")
    try:
        send(DATA, args.group, args.port, args.interface, args.ttl)
    except OSError as error:
        raise RocError(f"cannot send to {args.group}:{args.port}: {error.strerror or error} (is there a multicast "
                       "route? try --interface ADDRESS)") from None
    if args.format == "json":
        render({"group": args.group, "port": args.port, "data": DATA.decode()}, args.format)
    return 0
