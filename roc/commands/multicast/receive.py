"""roc multicast receive: wait for one UDP multicast datagram and say who sent it (like ros2 multicast
receive); --timeout makes it give up (exit 1)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.doctor.network import DEFAULT_GROUP, DEFAULT_PORT, receive
from roc.errors import RocError, UsageError
from roc.render import print_text, render


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value <= 0:
        raise argparse.ArgumentTypeError("value must be a positive integer")
    return value


def add_multicast_arguments(parser: argparse.ArgumentParser) -> None:
    """The group, port and interface options of the multicast verbs (ros2's, and --interface)."""
    parser.add_argument("--group", default=DEFAULT_GROUP,
                        help=f"the multicast group address (default: {DEFAULT_GROUP})")
    parser.add_argument("--port", type=_positive, default=DEFAULT_PORT,
                        help=f"the multicast port (default: {DEFAULT_PORT})")
    parser.add_argument("--interface", metavar="ADDRESS",
                        help="IPv4 address of the interface to use (default: the system's choice)")
    add_format_argument(parser)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_multicast_arguments(parser)
    parser.add_argument("--timeout", type=float, metavar="SECONDS", help="give up after this long (default: wait)")


def run(args: argparse.Namespace) -> int:
    if args.timeout is not None and args.timeout <= 0:
        raise UsageError("--timeout: give a number of seconds above 0")
    if args.format == "text":
        print_text("Waiting for UDP multicast datagram...\n")
    try:
        data, (host, port) = receive(args.group, args.port, args.interface, args.timeout)
    except TimeoutError:
        raise RocError(f"no datagram to {args.group}:{args.port} within {args.timeout:g} s") from None
    except OSError as error:
        raise RocError(f"cannot join {args.group} on port {args.port}: {error.strerror or error} "
                       "(try --interface ADDRESS)") from None
    text = data.decode("utf-8", "replace")
    render({"host": host, "port": port, "data": text}, args.format, [f"Received from {host}:{port}: '{text}'"])
    return 0
