"""How many participants a fresh participant must discover before its graph is complete, so that a
first query answers as soon as it has seen everything instead of after a fixed wait.

Two facts make the local part exact:
- every RTPS participant binds the metatraffic unicast UDP port its domain and participant id give
  (RTPS 9.6.1.1: 7400 + 250 * domain + 10 + 2 * id) and the user-data port above it, so
  ``/proc/net/udp`` tells how many participants this host has in a domain, whether or not they have
  been heard yet;
- every ROS participant has one writer on ``ros_discovery_info`` (rmw_dds_common), and Fast DDS's GUID
  prefix carries the writer's host id (bytes 2-3) and process id (bytes 4-5, little-endian), so the
  writers seen tell which of those participants have been discovered.

A participant discovered is not wholly known yet: its nodes come in its ``ros_discovery_info`` message
(under load 0.1 s and more after its writer), and each endpoint in an announcement of its own, which
may come later still. It is once its message has come and every node and endpoint GID the message
lists has been discovered (``incomplete_participants``; the message is read by
roc.ros.discovery_info).

A fresh participant's first announcement goes out before Fast DDS listens, so it would hear some of
them only at their next periodic announcement: it asks them to announce themselves again
(``ask_local_participants_to_announce``, roc.ros.spdp), with input buffers large enough for all their
answers at once (``enlarge_input_buffers``).

Participants on other hosts (a discovery range beyond this host) cannot be counted: the caller waits
for the graph to go quiet for them. This module reads /proc and rclpy endpoint infos and sends UDP
datagrams; it never imports rclpy itself (``roc tui`` finds each node's process with it too).
"""

from __future__ import annotations

import contextlib
import os
import socket
from collections.abc import Container, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from roc.ros.spdp import stand_in_announcement

PORT_BASE = 7400
DOMAIN_GAIN = 250
PARTICIPANT_GAIN = 2
METATRAFFIC_UNICAST_OFFSET = 10
USER_PORT_OFFSET = 1  # a participant's user-data unicast port, above its metatraffic one (RTPS 9.6.1.1)
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"  # rmw_dds_common's name for the node of an endpoint not told yet
MAX_PARTICIPANT_ID = 119  # the highest id whose ports stay within the domain's 250
DISCOVERY_TOPIC = "ros_discovery_info"  # a DDS name, outside ROS's conventions (no rt/ prefix)
FAST_DDS_VENDOR = b"\x01\x0f"
UDP_TABLES = (Path("/proc/net/udp"), Path("/proc/net/udp6"))
INPUT_BUFFER_BYTES = 4 * 1024 * 1024  # what a participant's discovery socket asks for (enlarge_input_buffers)


def is_metatraffic_port(port: int, domain_id: int) -> bool:
    """A metatraffic unicast port of a participant of ``domain_id``."""
    offset = port - PORT_BASE - DOMAIN_GAIN * domain_id - METATRAFFIC_UNICAST_OFFSET
    return 0 <= offset <= PARTICIPANT_GAIN * MAX_PARTICIPANT_ID and offset % PARTICIPANT_GAIN == 0


def is_participant_port(port: int, domain_id: int, bound: Container[int]) -> bool:
    """``port`` is a participant's metatraffic unicast port in ``domain_id``, ``bound`` holding the ports
    bound beside it: a participant binds its user data's port above too, which tells it from any
    process's socket on an ephemeral port that happens to be one of the domain's (domains 102 to 214 lie
    among Linux's ephemeral ports)."""
    return is_metatraffic_port(port, domain_id) and port + USER_PORT_OFFSET in bound


def process_bits(prefix: bytes) -> int | None:
    """The 16 low bits of the process id in a Fast DDS GUID prefix (None for another vendor's)."""
    if prefix[:2] != FAST_DDS_VENDOR or len(prefix) < 6:
        return None
    return int.from_bytes(prefix[4:6], "little")


def _own_sockets() -> dict[int, str]:
    """This process's sockets: file descriptor and inode."""
    sockets = {}
    for fd in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:["):
            sockets[int(fd)] = target[len("socket:["):-1]
    return sockets


def own_socket_inodes() -> set[str]:
    """The inodes of this process's sockets (its own participants' ports are not peers)."""
    return set(_own_sockets().values())


def metatraffic_sockets(domain_id: int, tables: tuple[Path, ...] = UDP_TABLES) -> list[tuple[str | None, int, bool]]:
    """The metatraffic unicast sockets bound on this host (this network namespace) in ``domain_id``:
    (IPv4 address, None for IPv6; port; whether this process owns it), told as is_participant_port
    tells. Raises OSError when the UDP tables cannot be read (not Linux)."""
    own = own_socket_inodes()
    bound = []
    for table in tables:
        for line in table.read_text().splitlines()[1:]:
            fields = line.split()
            address, port_hex = fields[1].rsplit(":", 1)
            bound.append((address, int(port_hex, 16), fields[9]))
    ports = {port for _, port, _ in bound}
    sockets = []
    for address, port, inode in bound:
        if is_participant_port(port, domain_id, ports):
            ipv4 = ".".join(str(b) for b in reversed(bytes.fromhex(address))) if len(address) == 8 else None
            sockets.append((ipv4, port, inode in own))
    return sockets


def local_participant_count(domain_id: int, tables: tuple[Path, ...] = UDP_TABLES) -> int | None:
    """How many participants of other processes on this host (this network namespace) are in
    ``domain_id``; None when the UDP tables cannot be read (not Linux)."""
    try:
        return len({port for _, port, own in metatraffic_sockets(domain_id, tables) if not own})
    except (OSError, IndexError, ValueError):
        return None


def ask_local_participants_to_announce(domain_id: int, tables: tuple[Path, ...] = UDP_TABLES) -> int:
    """Send every participant of another process on this host in ``domain_id`` the announcement of a
    stand-in participant whose locators are this process's participants' discovery ports, so that each
    announces itself to them at once (why: roc.ros.spdp). Returns how many were asked (0 where the UDP
    tables cannot be read)."""
    try:
        sockets = metatraffic_sockets(domain_id, tables)
    except (OSError, IndexError, ValueError):
        return 0
    ours = sorted({(_reachable(address), port) for address, port, own in sockets if own and address})
    peers = sorted({(_reachable(address), port) for address, port, own in sockets if not own and address})
    if not ours or not peers:
        return 0
    message = stand_in_announcement(domain_id, ours)
    asked = 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        for peer in peers:
            try:
                sender.sendto(message, peer)
                asked += 1
            except OSError:  # gone meanwhile, or a full buffer: that one is heard at its next announcement
                continue
    return asked


def enlarge_input_buffers(domain_id: int, size: int = INPUT_BUFFER_BYTES) -> int:
    """Ask for ``size`` bytes of input buffer on this process's metatraffic unicast sockets in
    ``domain_id`` (is_participant_port: not a sender's ephemeral socket) where they have less
    (Linux grants at most net.core.rmem_max); returns how many were asked. Why: a fresh participant asks
    every process of this host at once (above), so all of them send it their endpoints' announcements at
    the same moment, each as its own datagram: with the demo graph's three processes more than the
    system's default buffer (Linux: 208 KiB) holds. A datagram lost there is heard only when its
    writer's next heartbeat brings it again, up to 1 s later. This is done from outside Fast DDS because
    rmw replaces Fast DDS's transports on the LOCALHOST range, where a profile's listenSocketBufferSize
    is not applied."""
    asked = 0
    with contextlib.ExitStack() as opened:
        by_port: dict[int, list[socket.socket]] = {}
        for fd in _own_sockets():
            sock = _datagram_socket(fd)
            if sock is not None:
                opened.enter_context(sock)
                by_port.setdefault(sock.getsockname()[1], []).append(sock)
        for port, sockets in by_port.items():
            if not is_participant_port(port, domain_id, by_port):
                continue
            for sock in sockets:
                try:
                    if sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) < size:
                        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, size)
                        asked += 1
                except OSError:
                    continue
    return asked


def _datagram_socket(fd: int) -> socket.socket | None:
    """A copy of descriptor ``fd`` as a socket when it is a bound IP datagram socket, else None."""
    try:
        copy = os.dup(fd)
    except OSError:  # closed meanwhile
        return None
    try:
        sock = socket.socket(fileno=copy)
    except OSError:  # no longer a socket
        os.close(copy)
        return None
    try:
        if sock.type == socket.SOCK_DGRAM and sock.family in (socket.AF_INET, socket.AF_INET6) \
                and sock.getsockname()[1]:
            return sock
    except OSError:
        pass
    sock.close()
    return None


def _reachable(address: str) -> str:
    """The address to send to for a socket bound to ``address`` (any address: this host's loopback)."""
    return "127.0.0.1" if address == "0.0.0.0" else address


def discovered_local_peers(writers: list[Any], pid: int) -> int | None:
    """How many participants of other processes on this host are among ``writers`` (rclpy endpoint
    infos of the ``ros_discovery_info`` writers); None when this process's own writer is not among
    them yet or the middleware is not Fast DDS (its GUID layout is unknown)."""
    prefixes = {bytes(info.endpoint_gid)[:12] for info in writers}
    own = {p for p in prefixes if process_bits(p) == pid & 0xFFFF}
    if not own:
        return None
    host = next(iter(own))[2:4]
    return sum(1 for p in prefixes - own if process_bits(p) is not None and p[2:4] == host)


@dataclass(frozen=True)
class Told:
    """What a participant's latest ``ros_discovery_info`` message lists (roc.ros.discovery_info): its
    nodes as (namespace, name) and the GIDs of their endpoints."""

    nodes: frozenset[tuple[str, str]]
    endpoints: frozenset[bytes]


def incomplete_participants(writers: list[Any], told: Mapping[bytes, Told], endpoints: set[bytes],
                            nodes: set[tuple[str, str]], pid: int) -> int:
    """How many participants of other processes, whose ``ros_discovery_info`` writer is among ``writers``
    (rclpy endpoint infos), are not wholly discovered yet: their writer's message (``told``, by writer
    GID) has not come, or it lists a node not among ``nodes`` (namespace, name) or an endpoint whose
    GID is not among ``endpoints``."""
    incomplete = 0
    for info in writers:
        gid = bytes(info.endpoint_gid)
        if process_bits(gid[:12]) == pid & 0xFFFF:
            continue
        latest = told.get(gid)
        if latest is None or not latest.nodes <= nodes or not latest.endpoints <= endpoints:
            incomplete += 1
    return incomplete
