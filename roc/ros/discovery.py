"""How many participants a fresh participant must discover before its graph is complete, so that a
first query answers as soon as it has seen everything instead of after a fixed wait.

Two facts make the local part exact:
- every RTPS participant binds the metatraffic unicast UDP port its domain and participant id give
  (RTPS 9.6.1.1: 7400 + 250 * domain + 10 + 2 * id), so ``/proc/net/udp`` tells how many participants
  this host has in a domain, whether or not they have been heard yet;
- every ROS participant has one writer on ``ros_discovery_info`` (rmw_dds_common), and Fast DDS's GUID
  prefix carries the writer's host id (bytes 2-3) and process id (bytes 4-5, little-endian), so the
  writers seen tell which of those participants have been discovered.

Participants on other hosts (a discovery range beyond this host) cannot be counted: the caller waits
for the graph to go quiet for them. This module reads /proc and rclpy endpoint infos; it never
imports rclpy itself (``roc tui`` finds each node's process with it too).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

PORT_BASE = 7400
DOMAIN_GAIN = 250
PARTICIPANT_GAIN = 2
METATRAFFIC_UNICAST_OFFSET = 10
MAX_PARTICIPANT_ID = 119  # the highest id whose ports stay within the domain's 250
DISCOVERY_TOPIC = "ros_discovery_info"  # a DDS name, outside ROS's conventions (no rt/ prefix)
FAST_DDS_VENDOR = b"\x01\x0f"
UDP_TABLES = (Path("/proc/net/udp"), Path("/proc/net/udp6"))


def is_metatraffic_port(port: int, domain_id: int) -> bool:
    """A metatraffic unicast port of a participant of ``domain_id``."""
    offset = port - PORT_BASE - DOMAIN_GAIN * domain_id - METATRAFFIC_UNICAST_OFFSET
    return 0 <= offset <= PARTICIPANT_GAIN * MAX_PARTICIPANT_ID and offset % PARTICIPANT_GAIN == 0


def process_bits(prefix: bytes) -> int | None:
    """The 16 low bits of the process id in a Fast DDS GUID prefix (None for another vendor's)."""
    if prefix[:2] != FAST_DDS_VENDOR or len(prefix) < 6:
        return None
    return int.from_bytes(prefix[4:6], "little")


def own_socket_inodes() -> set[str]:
    """The inodes of this process's sockets (its own participants' ports are not peers)."""
    inodes = set()
    for fd in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:["):
            inodes.add(target[len("socket:["):-1])
    return inodes


def local_participant_count(domain_id: int, tables: tuple[Path, ...] = UDP_TABLES) -> int | None:
    """How many participants of other processes on this host (this network namespace) are in
    ``domain_id``; None when the UDP tables cannot be read (not Linux)."""
    own = own_socket_inodes()
    bound: set[int] = set()
    try:
        for table in tables:
            for line in table.read_text().splitlines()[1:]:
                fields = line.split()
                port = int(fields[1].rsplit(":", 1)[1], 16)
                if is_metatraffic_port(port, domain_id) and fields[9] not in own:
                    bound.add(port)
    except (OSError, IndexError, ValueError):
        return None
    return len(bound)


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
