"""How a fresh participant knows its graph is complete (roc.ros.discovery) and how it asks this host's
participants to announce themselves (roc.ros.spdp): unit tests on made-up /proc tables and GUIDs, and a
real Fast DDS participant answering the stand-in's announcement."""

from __future__ import annotations

import socket
import struct
from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, start_nodes, stop_all

from roc import distribution
from roc.ros.discovery import (
    UNKNOWN_NODE,
    ask_local_participants_to_announce,
    discovered_local_peers,
    local_participant_count,
    metatraffic_sockets,
    own_socket_inodes,
    process_bits,
    unheard_participants,
)
from roc.ros.spdp import SPDP_WRITER, stand_in_announcement

SLOT = 67

UDP_HEADER = "  sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ref pointer drops\n"


def _udp_line(port: int, inode: str, address: str = "00000000") -> str:
    return f"  1: {address}:{port:04X} 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 {inode} 2 0 0\n"


def test_this_hosts_participants_are_counted_by_their_bound_discovery_ports(tmp_path: Path) -> None:
    own = next(iter(own_socket_inodes() or {"none"}))
    table = tmp_path / "udp"
    # domain 3: participants 0 and 2 of other processes, participant 1 this process's own; 7411 and
    # 8161 are another domain's and a user traffic port, 7000 anything else
    table.write_text(UDP_HEADER + _udp_line(8160, "11") + _udp_line(8164, "12") + _udp_line(8162, own)
                     + _udp_line(8161, "13") + _udp_line(7410, "14") + _udp_line(7000, "15"))
    assert local_participant_count(3, (table,)) == 2
    assert local_participant_count(0, (table,)) == 1
    assert local_participant_count(3, (tmp_path / "missing",)) is None


class Writer:
    def __init__(self, prefix_hex: str):
        self.endpoint_gid = list(bytes.fromhex(prefix_hex + "000001c3"))


def test_discovered_peers_are_the_other_fast_dds_participants_of_this_host() -> None:
    pid = 0x7322
    ours = Writer("010f7f01" "2273" "2073" "00000000")
    writers = [ours, Writer("010f7f01" "8272" "ae01" "00000000"), Writer("010f7f01" "8272" "ae01" "01000000"),
               Writer("010fc0a8" "1111" "0000" "00000000"),  # another host
               Writer("01107f01" "1111" "0000" "00000000")]  # another vendor
    assert discovered_local_peers(writers, pid) == 2  # one process, two participants
    assert discovered_local_peers(writers[1:], pid) is None  # this process's own writer not seen yet


class Endpoint(Writer):
    def __init__(self, prefix_hex: str, node_name: str):
        super().__init__(prefix_hex)
        self.node_name = node_name


def test_a_participant_is_heard_once_an_endpoint_has_its_node_or_a_roc_node_names_its_process() -> None:
    pid = 0x7322
    ours, talker, listener, roc_daemon = ("010f7f01" "2273" "2073" "00000000", "010f7f01" "8272" "ae01" "00000000",
                                          "010f7f01" "8272" "b001" "00000000", "010f7f01" "3412" "9999" "00000000")
    writers = [Writer(prefix) for prefix in (ours, talker, listener, roc_daemon)]
    # the talker's node is told; the listener's endpoints are seen before its node; roc's daemon has none
    endpoints = [Endpoint(talker, "talker"), Endpoint(listener, UNKNOWN_NODE)]
    assert unheard_participants(writers, endpoints, ["talker"], pid) == 2
    assert unheard_participants(writers, endpoints, ["talker", f"_roc_{0x11234}"], pid) == 1  # pid's low 16 bits
    endpoints.append(Endpoint(listener, "listener"))
    assert unheard_participants(writers, endpoints, ["talker", "listener", f"_roc_{0x1234}"], pid) == 0
    assert unheard_participants(writers, [], [], pid) == 3  # nothing told yet: only this process's own is not waited for


def _locator(address: str, port: int) -> bytes:
    """An RTPS UDPv4 locator (RTPS 9.3.2): kind 1, port, the address in the last 4 of 16 bytes."""
    return struct.pack("<iI", 1, port) + bytes(12) + socket.inet_aton(address)


def _bound_at_free_participant_ports(domain: int, count: int) -> list[socket.socket]:
    """UDP sockets on 127.0.0.1 at the metatraffic ports of the first free participant ids of ``domain``."""
    sockets = []
    for participant in range(120):
        if len(sockets) == count:
            break
        candidate = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            candidate.bind(("127.0.0.1", 7400 + 250 * domain + 10 + 2 * participant))
        except OSError:
            candidate.close()
            continue
        sockets.append(candidate)
    return sockets


def test_the_other_processes_participants_are_asked_to_announce_themselves_to_ours(tmp_path: Path) -> None:
    """Domain 200 is above the tests' domains; the table makes one socket this process's participant and
    the other another process's."""
    ours, theirs = _bound_at_free_participant_ports(200, 2)
    try:
        own_inode = next(iter(own_socket_inodes()))
        table = tmp_path / "udp"
        loopback = "0100007F"  # 127.0.0.1 as the kernel writes it
        table.write_text(UDP_HEADER + _udp_line(ours.getsockname()[1], own_inode, loopback)
                         + _udp_line(theirs.getsockname()[1], "99", loopback))
        assert metatraffic_sockets(200, (table,)) == [("127.0.0.1", ours.getsockname()[1], True),
                                                      ("127.0.0.1", theirs.getsockname()[1], False)]
        assert ask_local_participants_to_announce(200, (table,)) == 1
        theirs.settimeout(5)
        message = theirs.recv(65536)
        assert message.startswith(b"RTPS")
        assert _locator("127.0.0.1", ours.getsockname()[1]) in message
        assert struct.pack("<HHI", 0x000F, 4, 200) in message  # PID_DOMAIN_ID
        assert ask_local_participants_to_announce(200, (tmp_path / "missing",)) == 0
    finally:
        ours.close()
        theirs.close()


def test_a_fast_dds_participant_asked_announces_itself_to_the_stand_in_s_port(tmp_path: Path) -> None:
    """The real middleware reads the stand-in's announcement and answers with its own at once."""
    env = graph_env(SLOT, tmp_path)
    [node] = start_nodes([{"name": "asked"}], env)
    try:
        domain = int(env["ROS_DOMAIN_ID"])
        [port] = [port for _, port, own in metatraffic_sockets(domain) if not own]
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as listener:
            listener.bind(("127.0.0.1", 0))
            listener.settimeout(10)
            listener.sendto(stand_in_announcement(domain, [listener.getsockname()]), ("127.0.0.1", port))
            answer = listener.recv(65536)
        assert answer.startswith(b"RTPS")
        assert process_bits(answer[8:20]) == node.pid & 0xFFFF  # the header's GUID prefix: the node's participant
        assert SPDP_WRITER in answer  # a DATA(p) of its announcement writer
    finally:
        stop_all([node])


# Fast DDS profiles (Jazzy's 2.x, Kilted's 3.x namespace) of processes that announce themselves once a minute
RARE_ANNOUNCEMENTS = """<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="{namespace}">
  <profiles>
    <participant profile_name="rare" is_default_profile="true">
      <rtps>
        <builtin>
          <discovery_config>
            <leaseDuration><sec>120</sec></leaseDuration>
            <leaseAnnouncement><sec>60</sec></leaseAnnouncement>
          </discovery_config>
        </builtin>
      </rtps>
    </participant>
  </profiles>
</dds>
"""


@pytest.mark.slow
@pytest.mark.distro
def test_a_first_query_hears_processes_that_announce_themselves_once_a_minute(tmp_path: Path) -> None:
    """A fresh participant that lost their answers to its first announcement would wait a minute for
    them; asked, they answer at once. Three first queries of four such processes: complete each time."""
    current = distribution.current()
    namespace = "http://www.eprosima.com" if current.fastdds_major >= 3 else "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"
    profile = tmp_path / "rare.xml"
    profile.write_text(RARE_ANNOUNCEMENTS.format(namespace=namespace))
    env = graph_env(SLOT, tmp_path)
    names = [f"/rare{i}" for i in range(4)]
    processes = start_nodes([{"name": name[1:]} for name in names], {**env, current.profiles_variable: str(profile)})
    try:
        for _ in range(3):
            listed = roc("node", "list", "--no-daemon", "--spin-time", "20", env=env)
            assert listed.stdout.split() == names, listed.stderr
    finally:
        stop_all(processes)
