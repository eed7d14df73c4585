"""roc doctor hello: check that hosts hear each other (like ros2 doctor hello). Run it on several hosts:
each publishes "hello, it's me HOST" on a topic and sends it as a UDP multicast datagram, and every
print period says how many of each it heard from every other host."""

from __future__ import annotations

import argparse
import socket
import threading
import time
from collections import Counter
from typing import Any

from roc.cli.options import add_graph_arguments
from roc.doctor.network import DEFAULT_GROUP, DEFAULT_PORT, receiver, sender
from roc.errors import UsageError
from roc.render import print_json_line, print_text
from roc.ros.client import stream
from roc.ros.protocol import task_node_name

STRING = "std_msgs/msg/String"
QOS = {"profile": "system_default"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-t", "--topic", default="/canyouhearme", help="topic to publish on (default: /canyouhearme)")
    parser.add_argument("-ep", "--emit-period", type=float, default=0.1, metavar="N",
                        help="seconds between two messages and datagrams (default: 0.1)")
    parser.add_argument("-pp", "--print-period", type=float, default=1.0, metavar="N",
                        help="seconds between two summaries (default: 1.0)")
    parser.add_argument("--ttl", type=int, help="TTL of the multicast datagrams")
    parser.add_argument("-1", "--once", action="store_true", help="one emit period, one summary, then exit")
    parser.add_argument("--group", default=DEFAULT_GROUP, help=f"multicast group (default: {DEFAULT_GROUP})")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"multicast port (default: {DEFAULT_PORT})")
    parser.add_argument("--interface", metavar="ADDRESS",
                        help="IPv4 address of the interface to multicast on (default: the system's choice)")
    add_graph_arguments(parser)


class Summary:
    """What was sent and heard since the last summary; thread-safe."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.published = self.sent = 0
        self.subscribed: Counter[str] = Counter()
        self.received: Counter[str] = Counter()

    def take(self) -> dict[str, Any]:
        with self.lock:
            taken = {"published": self.published, "subscribed": dict(self.subscribed), "sent": self.sent,
                     "received": dict(self.received)}
            self.published = self.sent = 0
            self.subscribed, self.received = Counter(), Counter()
        return taken


def summary_lines(taken: dict[str, Any], args: argparse.Namespace) -> list[str]:
    """ros2 doctor hello's table."""
    def table(counts: dict[str, int]) -> list[str]:
        rows = [("", "Hostname", f"Msg Count /{args.print_period}s"), *(("", h, n) for h, n in counts.items())]
        return [f"{a:<15} {b:<20} {c!s:<10}" for a, b, c in rows]

    return ["MULTIMACHINE COMMUNICATION SUMMARY", f"Topic: {args.topic}, Published Msg Count: {taken['published']}",
            "Subscribed from:", *table(taken["subscribed"]),
            f"Multicast Group/Port: {args.group}/{args.port}, Sent Msg Count: {taken['sent']}",
            "Received from:", *table(taken["received"]), "-" * 60]


def _listen(args: argparse.Namespace, me: str, summary: Summary, stop: threading.Event) -> None:
    """Count the topic's messages from other hosts until ``stop``."""
    from roc.ros.cdr import decode

    events = stream("echo", {"topic": args.topic, "type": STRING, "qos": QOS}, use_daemon=not args.no_daemon,
                    heartbeats=True)
    for event in events:
        if stop.is_set():
            break
        for message in event.get("messages", []) if event["event"] == "messages" else []:
            host = decode(STRING, message["data"]).data.split()[-1]
            if host != me:
                with summary.lock:
                    summary.subscribed[host] += 1
    events.close()


def _receive(sock: socket.socket, me: str, summary: Summary, stop: threading.Event) -> None:
    """Count the multicast datagrams from other hosts until ``stop``."""
    sock.settimeout(0.2)
    while not stop.is_set():
        try:
            data = sock.recvfrom(4096)[0].decode("utf-8", "replace")
        except TimeoutError:
            continue
        except OSError:
            return
        host = data.split()[-1] if data.split() else ""
        if host and host != me:
            with summary.lock:
                summary.received[host] += 1


def run(args: argparse.Namespace) -> int:
    if args.emit_period <= 0 or args.print_period <= 0:
        raise UsageError("--emit-period and --print-period take a number of seconds above 0")
    from roc.ros.cdr import encode
    from roc.ros.types import message_class

    me = socket.gethostname()
    text = f"hello, it's me {me}"
    summary, stop = Summary(), threading.Event()
    listening = receiver(args.group, args.port, args.interface)
    sending = sender(args.interface, args.ttl)
    workers = [threading.Thread(target=_listen, args=(args, me, summary, stop), daemon=True),
               threading.Thread(target=_receive, args=(listening, me, summary, stop), daemon=True)]
    for worker in workers:
        worker.start()
    params = {"topic": args.topic, "type": STRING, "data": encode(message_class(STRING)(data=text)), "qos": QOS,
              "rate": 1.0 / args.emit_period, "times": 1 if args.once else 0, "keep_alive": args.emit_period,
              "node": task_node_name("doctor_hello")}
    printed = time.monotonic()
    try:
        for event in stream("publish", params, use_daemon=not args.no_daemon, heartbeats=True):
            if event["event"] == "published":
                sending.sendto(text.encode(), (args.group, args.port))
                with summary.lock:
                    summary.published += 1
                    summary.sent += 1
            if time.monotonic() - printed >= args.print_period:
                printed = time.monotonic()
                _print(summary.take(), args)
        if args.once:
            time.sleep(args.emit_period)  # what the others sent meanwhile
            _print(summary.take(), args)
    finally:
        stop.set()
        sending.close()
        for worker in workers:
            worker.join(timeout=2)
        listening.close()
    return 0


def _print(taken: dict[str, Any], args: argparse.Namespace) -> None:
    if args.format == "json":
        print_json_line({"topic": args.topic, "group": args.group, "port": args.port, **taken})
    else:
        print_text("\n".join(summary_lines(taken, args)) + "\n")
