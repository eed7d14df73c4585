"""How a fresh participant knows its graph is complete (roc.ros.discovery, roc.ros.discovery_info) and
how it asks this host's participants to announce themselves (roc.ros.spdp): unit tests on made-up /proc
tables and GUIDs; real participants telling their nodes and endpoints on ros_discovery_info; a real
Fast DDS participant answering the stand-in's announcement."""

from __future__ import annotations

import json
import socket
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.graph import NODE_SCRIPT, graph_env, read_line, roc, start_nodes, stop_all

from roc import distribution
from roc.ros.discovery import (
    INPUT_BUFFER_BYTES,
    Told,
    ask_local_participants_to_announce,
    discovered_local_peers,
    enlarge_input_buffers,
    incomplete_participants,
    local_participant_count,
    metatraffic_sockets,
    own_socket_inodes,
    process_bits,
)
from roc.ros.spdp import SPDP_WRITER, stand_in_announcement

SLOT = 67

UDP_HEADER = "  sl  local_address rem_address   st tx_queue rx_queue tr tm->when retrnsmt   uid  timeout inode ref pointer drops\n"


def _udp_line(port: int, inode: str, address: str = "00000000") -> str:
    return f"  1: {address}:{port:04X} 00000000:0000 07 00000000:00000000 00:00000000 00000000     0        0 {inode} 2 0 0\n"


def test_this_hosts_participants_are_counted_by_their_bound_discovery_ports_not_ephemeral_ones(
        tmp_path: Path) -> None:
    own = next(iter(own_socket_inodes() or {"none"}))
    table = tmp_path / "udp"
    # domain 3: participants 0 and 2 of other processes, participant 1 this process's own, each with its
    # user-data port above; 8166 some process's ephemeral socket (no port above it); 7410 another
    # domain's participant, 7000 anything else
    table.write_text(UDP_HEADER + "".join(_udp_line(port, inode) for port, inode in (
        (8160, "11"), (8161, "11"), (8164, "12"), (8165, "12"), (8162, own), (8163, own), (8166, "13"),
        (7410, "14"), (7411, "14"), (7000, "15"))))
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


def _told(nodes: list[str], endpoints: list[str]) -> Told:
    return Told(nodes=frozenset(("/", name) for name in nodes),
                endpoints=frozenset(bytes.fromhex(gid) for gid in endpoints))


def test_a_participant_is_wholly_known_once_its_message_has_come_and_all_it_lists_is_discovered() -> None:
    pid = 0x7322
    ours, talker, listener = ("010f7f01" "2273" "2073" "00000000", "010f7f01" "8272" "ae01" "00000000",
                              "010f7f01" "8272" "b001" "00000000")
    writers = [Writer(prefix) for prefix in (ours, talker, listener)]
    gid = {writer: bytes(writer.endpoint_gid) for writer in writers}
    talker_pub, listener_sub = talker + "00000103", listener + "00000104"
    told = {gid[writers[1]]: _told(["talker"], [talker_pub]), gid[writers[2]]: _told(["listener"], [listener_sub])}
    nodes = {("/", "talker"), ("/", "listener")}
    endpoints = {bytes.fromhex(talker_pub), bytes.fromhex(listener_sub)}
    assert incomplete_participants(writers, told, endpoints, nodes, pid) == 0
    # the listener's subscription is told but not discovered yet: only the listener is incomplete
    assert incomplete_participants(writers, told, {bytes.fromhex(talker_pub)}, nodes, pid) == 1
    # a node told that the graph does not show yet
    assert incomplete_participants(writers, told, endpoints, {("/", "talker")}, pid) == 1
    # no message from the listener's writer yet; this process's own writer is never waited for
    assert incomplete_participants(writers, {gid[writers[1]]: told[gid[writers[1]]]}, endpoints, nodes, pid) == 1
    assert incomplete_participants(writers, {}, set(), set(), pid) == 2
    assert incomplete_participants(writers, {}, set(), set(), 0x1111) == 3  # another process: ours is a peer


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
        table.write_text(UDP_HEADER + "".join(_udp_line(port + offset, inode, loopback) for port, inode in (
            (ours.getsockname()[1], own_inode), (theirs.getsockname()[1], "99")) for offset in (0, 1)))
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


def test_this_process_s_discovery_sockets_are_enlarged_and_no_other_socket() -> None:
    """Domain 201, above the tests' domains: a participant's discovery socket with its user-data socket
    above it; a sender's socket that happens to be at another discovery port (no user-data port above
    it, as Fast DDS's own senders on ephemeral ports); and one on no discovery port."""
    discovery, sender = _bound_at_free_participant_ports(201, 2)
    user_data = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    other = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        user_data.bind(("127.0.0.1", discovery.getsockname()[1] + 1))
        other.bind(("127.0.0.1", 0))
        for sock in (discovery, sender, user_data, other):
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 65536)
        small = other.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
        assert enlarge_input_buffers(201) == 1
        granted = min(INPUT_BUFFER_BYTES, int(Path("/proc/sys/net/core/rmem_max").read_text()))
        assert discovery.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) == 2 * granted  # Linux doubles it
        assert [sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) for sock in (sender, user_data, other)] \
            == [small] * 3
        assert enlarge_input_buffers(201) == (0 if 2 * granted >= INPUT_BUFFER_BYTES else 1)  # not when as large
    finally:
        for sock in (discovery, sender, user_data, other):
            sock.close()


@pytest.mark.slow  # a node of its own (the quick loop stays under 45 s)
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


def _printed_by(script: str, env: dict[str, str]) -> dict:
    """The JSON ``script`` prints, run by a Python process of its own in ``env``."""
    ran = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=60)
    assert ran.returncode == 0, ran.stderr
    return json.loads(ran.stdout)


# In a process of its own: what roc's ros_discovery_info reader tells of the talker's participant, beside
# what the rmw graph cache shows of the talker's endpoints once it has discovered them all
TOLD_AND_DISCOVERED = """
import json, time
from roc.ros.discovery_info import DiscoveryInfoReader
from roc.ros.graph import Graph

graph = Graph()
reader = DiscoveryInfoReader(graph.node)
node = graph.node
deadline = time.monotonic() + 20
while True:
    told = [t for t in reader.take().values() if ("/", "talker") in t.nodes]
    discovered = {bytes(info.endpoint_gid).hex()
                  for name, _ in node.get_topic_names_and_types(no_demangle=True)
                  for info in (*node.get_publishers_info_by_topic(name, no_mangle=True),
                               *node.get_subscriptions_info_by_topic(name, no_mangle=True))
                  if info.node_name == "talker"}
    if told and {gid.hex() for gid in told[0].endpoints} == discovered or time.monotonic() > deadline:
        break
    time.sleep(0.1)
reader.close()
graph.close()
print(json.dumps({"told": [{"nodes": sorted(t.nodes), "endpoints": sorted(gid.hex() for gid in t.endpoints)}
                           for t in told], "discovered": sorted(discovered)}))
"""


@pytest.mark.slow
@pytest.mark.distro
def test_a_participant_tells_on_ros_discovery_info_each_endpoint_the_graph_discovers_for_its_node(tmp_path: Path) -> None:
    """rmw's graph cache, reading the same messages, is the oracle: the GIDs roc's reader is told for the
    talker are those of the talker's endpoints the middleware discovered."""
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}],
                              "services": [{"name": "reset", "type": "std_srvs/srv/Trigger"}]}], env)
    try:
        seen = _printed_by(TOLD_AND_DISCOVERED, env)
    finally:
        stop_all(processes)
    [told] = seen["told"]
    assert told["nodes"] == [["/", "talker"]]
    # rosout, parameter events, chatter, and the requests and replies of reset and the parameter services
    assert len(seen["discovered"]) > 10
    assert told["endpoints"] == seen["discovered"]


# In a process of its own: how long a fresh participant's discovery waits, at most 1 s, and the nodes it sees
FIRST_DISCOVERY = """
import json, time
from roc.ros.graph import Graph

graph = Graph()
start = time.monotonic()
graph.wait_for_discovery(1.0)
waited = time.monotonic() - start
nodes = sorted(name for name, _ in graph.node.get_node_names_and_namespaces())
graph.close()
print(json.dumps({"waited": waited, "nodes": nodes}))
"""


@pytest.mark.slow
@pytest.mark.distro
def test_a_first_query_waits_for_an_endpoint_a_participant_told_but_never_announced(tmp_path: Path) -> None:
    """A late endpoint, made lasting: node /ghost is told with a writer no participant announces. Every
    other sign of a complete graph holds (each participant heard, each endpoint's node known), so
    only the endpoints told keep the wait going, to its end."""
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}],
                            env)
    teller = subprocess.Popen([sys.executable, str(NODE_SCRIPT.with_name("ghost_teller.py"))], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    processes.append(teller)
    try:
        assert read_line(teller) == "ready\n"
        seen = _printed_by(FIRST_DISCOVERY, env)
    finally:
        stop_all(processes)
    assert "ghost" in seen["nodes"] and "talker" in seen["nodes"]  # the ghost's message did come
    assert seen["waited"] >= 1.0
