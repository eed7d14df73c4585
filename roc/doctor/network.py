"""The network side of ``roc doctor``, ``roc doctor hello`` and ``roc multicast``: the interfaces and
their flags, UDP multicast datagrams sent and received (ros2 multicast's group and port), and how large
a UDP socket's input buffer may grow."""

from __future__ import annotations

import fcntl
import os
import socket
import struct
import time
from pathlib import Path
from typing import Any

import psutil

from roc.doctor.findings import Finding
from roc.ros.discovery import INPUT_BUFFER_BYTES

CATEGORY = "network"
DEFAULT_GROUP = "225.0.0.1"
DEFAULT_PORT = 49150
SIOCGIFFLAGS = 0x8913  # Linux's ioctl for an interface's flags
FLAG_BITS = {"UP": 0, "BROADCAST": 1, "LOOPBACK": 3, "POINTOPOINT": 4, "RUNNING": 6, "MULTICAST": 12}
SELF_TEST_SECONDS = 1.0
RMEM_MAX = Path("/proc/sys/net/core/rmem_max")  # Linux's bound on a socket's input buffer


def interface_flags(name: str) -> set[str]:
    """The named flags of an interface (UP, LOOPBACK, MULTICAST, ...), empty when it has none to read."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            result = fcntl.ioctl(probe.fileno(), SIOCGIFFLAGS, struct.pack("256s", name.encode()[:15]))
        except OSError:
            return set()
    flags = struct.unpack("H", result[16:18])[0]
    return {flag for flag, bit in FLAG_BITS.items() if flags & (1 << bit)}


def interfaces() -> list[dict[str, Any]]:
    """Each interface: name, flags, IPv4 and IPv6 addresses, MTU."""
    stats = psutil.net_if_stats()
    found = []
    for name, addresses in sorted(psutil.net_if_addrs().items()):
        found.append({"name": name, "flags": sorted(interface_flags(name)),
                      "inet4": [a.address for a in addresses if a.family == socket.AF_INET],
                      "inet6": [a.address for a in addresses if a.family == socket.AF_INET6],
                      "mtu": stats[name].mtu if name in stats else None})
    return found


def _membership(group: str, interface: str | None) -> bytes:
    return struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton(interface or "0.0.0.0"))


def sender(interface: str | None = None, ttl: int | None = None) -> socket.socket:
    """A UDP socket for multicast datagrams, out of ``interface`` (an IPv4 address) when given."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    if ttl is not None:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, struct.pack("b", ttl))
    if interface:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(interface))
    return sock


def receiver(group: str = DEFAULT_GROUP, port: int = DEFAULT_PORT, interface: str | None = None) -> socket.socket:
    """A UDP socket that has joined ``group`` on ``port`` (shared with other receivers, as ros2's)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.bind(("", port))
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, _membership(group, interface))
    except OSError:
        sock.close()
        raise
    return sock


def send(data: bytes, group: str = DEFAULT_GROUP, port: int = DEFAULT_PORT, interface: str | None = None,
         ttl: int | None = None) -> None:
    with sender(interface, ttl) as sock:
        sock.sendto(data, (group, port))


def receive(group: str = DEFAULT_GROUP, port: int = DEFAULT_PORT, interface: str | None = None,
            timeout: float | None = None) -> tuple[bytes, tuple[str, int]]:
    """The next datagram sent to ``group``:``port`` and who sent it; TimeoutError after ``timeout`` s."""
    with receiver(group, port, interface) as sock:
        sock.settimeout(timeout)
        data, address = sock.recvfrom(4096)
    return data, address


def multicast_self_test(interface: str | None = None) -> str | None:
    """Why a multicast datagram this host sends does not come back to it, None when it does."""
    token = f"roc doctor {os.getpid()} {time.monotonic()}".encode()
    try:
        with receiver(DEFAULT_GROUP, 0, interface) as listening:
            port = listening.getsockname()[1]
            send(token, DEFAULT_GROUP, port, interface, ttl=1)
            deadline = time.monotonic() + SELF_TEST_SECONDS
            while (left := deadline - time.monotonic()) > 0:
                listening.settimeout(left)
                if listening.recvfrom(4096)[0] == token:
                    return None
    except TimeoutError:
        pass
    except OSError as error:
        return error.strerror or str(error)
    return f"a datagram sent to {DEFAULT_GROUP} did not come back within {SELF_TEST_SECONDS:g} s"


def socket_buffer_check(rmem_max: Path = RMEM_MAX) -> Finding | None:
    """Whether a participant's discovery socket may grow to what roc's ask for
    (roc.ros.discovery.enlarge_input_buffers); None where the bound cannot be read (not Linux)."""
    try:
        bound = int(rmem_max.read_text())
    except (OSError, ValueError):
        return None
    if bound >= INPUT_BUFFER_BYTES:
        return Finding(CATEGORY, "socket buffers", "ok", f"input sockets may grow to {bound // 1024} KiB")
    return Finding(CATEGORY, "socket buffers", "info",
                   f"net.core.rmem_max is {bound // 1024} KiB: a burst of discovery data (many endpoints "
                   "announced at once) can overflow a participant's input socket and be heard only at "
                   "the next heartbeat, up to 1 s later",
                   f"sudo sysctl -w net.core.rmem_max={INPUT_BUFFER_BYTES} (ROS 2's DDS tuning guide)")


def checks(discovery_range: str) -> list[Finding]:
    """Interfaces (loopback, others, multicast) and a multicast round trip; what only matters for
    discovery beyond this host is a warning or error only when the discovery range is SUBNET."""
    found = interfaces()
    up = [i for i in found if "UP" in i["flags"]]
    loopback = [i["name"] for i in up if "LOOPBACK" in i["flags"]]
    others = [i["name"] for i in up if "LOOPBACK" not in i["flags"] and i["inet4"] + i["inet6"]]
    multicast = [i["name"] for i in up if "MULTICAST" in i["flags"]]
    subnet = discovery_range == "SUBNET"
    findings = []
    if not loopback:
        findings.append(Finding(CATEGORY, "interfaces", "error", "no loopback interface is up",
                                "bring it up: ip link set lo up"))
    if not others:
        findings.append(Finding(CATEGORY, "interfaces", "warning" if subnet else "info",
                                "only the loopback interface is up: no other machine can be reached",
                                "connect a network, or use ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST" if subnet else ""))
    elif not multicast:
        findings.append(Finding(CATEGORY, "interfaces", "warning" if subnet else "info",
                                "no interface has multicast enabled: DDS discovery cannot find other machines",
                                "enable multicast (ip link set DEV multicast on) or list peers in ROS_STATIC_PEERS"))
    if not findings:
        findings.append(Finding(CATEGORY, "interfaces", "ok", ", ".join(
            f"{i['name']} ({', '.join(i['inet4'] or i['inet6'])})" for i in up)))
    failure = multicast_self_test()
    if failure is None:
        findings.append(Finding(CATEGORY, "multicast", "ok", f"a datagram to {DEFAULT_GROUP} came back"))
    else:
        findings.append(Finding(CATEGORY, "multicast", "error" if subnet else "info", f"multicast does not work here: "
                                f"{failure}" + ("" if subnet else f" (not needed with {discovery_range} discovery)"),
                                "check the firewall (UDP, 224.0.0.0/4) and that a multicast route exists "
                                "(ip route get 239.255.0.1); `roc multicast send/receive` tests two hosts"
                                if subnet else ""))
    buffers = socket_buffer_check()
    if buffers is not None:
        findings.append(buffers)
    return findings


def report() -> list[tuple[str, str]]:
    """ros2 doctor's NETWORK CONFIGURATION: each interface's addresses, flags and MTU."""
    items: list[tuple[str, str]] = []
    for interface in interfaces():
        items.append(("device", interface["name"]))
        items += [("inet4", address) for address in interface["inet4"]]
        items += [("inet6", address) for address in interface["inet6"]]
        items += [("flags", ",".join(interface["flags"])), ("mtu", str(interface["mtu"]))]
    return items
