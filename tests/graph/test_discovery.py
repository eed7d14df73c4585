"""How a fresh participant knows its graph is complete (roc.ros.discovery, roc.ros.discovery_info) and
how it asks this host's participants to announce themselves (roc.ros.spdp), whatever their DDS vendor
(roc.ros.vendors): unit tests on made-up /proc tables and GUIDs; real participants telling their nodes
and endpoints on ros_discovery_info; a real participant answering the stand-in's announcement; first
queries on the suite's middleware and in a domain where Fast DDS and Cyclone DDS processes meet."""

from __future__ import annotations

import contextlib
import json
import os
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.graph import NODE_SCRIPT, graph_env, read_line, roc, start_nodes, stop_all
from helpers.rmw import CYCLONEDDS, FASTRTPS, on_middleware, require_cyclonedds, suite_middleware

from roc import distribution
from roc.errors import RocError
from roc.middleware import process_environment
from roc.ros import vendors
from roc.ros.discovery import (
    INPUT_BUFFER_BYTES,
    PASS_ON_TIMES,
    EndpointFetch,
    LocalParticipantProbe,
    Told,
    ask_local_participants_to_announce,
    enlarge_input_buffers,
    incomplete_participants,
    local_participant_count,
    local_peers_discovered,
    metatraffic_sockets,
    own_participant,
    own_socket_inodes,
    writers_to_prompt,
)
from roc.ros.spdp import (
    PID_DEFAULT_UNICAST_LOCATOR,
    SEDP_PUBLICATIONS,
    SEDP_SUBSCRIPTIONS,
    SPDP_WRITER,
    acknack_prompt,
    acknack_request,
    announced_locators,
    data_sequence_numbers,
    heartbeats,
    is_builtin,
    stand_in_announcement,
    undirected,
)
from roc.ros.vendors.fastdds import process_bits

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


FAST_DDS_PREFIX = "010f7f01" "8272" "ae01" "00000000"  # host id 7f01, pid bits 0x7282
CYCLONE_PREFIX = "0110" "26b8a480c105da044b55"  # no host, no pid


def test_a_participant_s_vendor_is_told_by_its_guid_prefix_or_its_middleware() -> None:
    assert vendors.of_prefix(bytes.fromhex(FAST_DDS_PREFIX)).name == "Fast DDS"
    assert vendors.of_prefix(bytes.fromhex(CYCLONE_PREFIX)).name == "Cyclone DDS"
    assert vendors.of_prefix(bytes.fromhex("0000" + CYCLONE_PREFIX[4:])) is None
    assert vendors.of_middleware("rmw_cyclonedds_cpp") == vendors.of_prefix(bytes.fromhex(CYCLONE_PREFIX))
    assert vendors.of_middleware("rmw_fastrtps_dynamic_cpp").name == "Fast DDS"
    assert vendors.of_middleware("rmw_zenoh_cpp") is None
    assert process_bits(bytes.fromhex(FAST_DDS_PREFIX)) == 0x7282  # Fast DDS's layout, in its vendor's module
    assert process_bits(bytes.fromhex(CYCLONE_PREFIX)) is None


def test_this_hosts_peers_are_discovered_once_each_that_answered_the_probe_has_a_discovery_writer() -> None:
    """Any vendor's prefixes: who is of this host comes from the probe's answers, not from a GUID layout."""
    fast, cyclone, remote = (bytes.fromhex(p) for p in (FAST_DDS_PREFIX, CYCLONE_PREFIX, "0110" + "ab" * 10))
    writers = [Writer(prefix.hex()) for prefix in (fast, cyclone, remote)]
    assert local_peers_discovered(2, {fast, cyclone}, writers) is True
    assert local_peers_discovered(2, {fast, cyclone}, writers[1:]) is False  # the Fast DDS one not discovered yet
    assert local_peers_discovered(2, {cyclone}, writers) is False  # one of the two ports has not answered yet
    assert local_peers_discovered(0, set(), []) is True  # alone on this host
    assert local_peers_discovered(None, {fast}, writers) is None  # cannot be counted (not Linux)


def _told(nodes: list[str], endpoints: list[str]) -> Told:
    return Told(nodes=frozenset(("/", name) for name in nodes),
                endpoints=frozenset(bytes.fromhex(gid) for gid in endpoints))


def test_a_participant_is_wholly_known_once_its_message_has_come_and_all_it_lists_is_discovered() -> None:
    """What a participant told is keyed by the participant its message names (Cyclone DDS's message info
    names no writer GUID); this process's own participant is told as any other."""
    ours, talker, listener = ("0110" "1111aaaa" "22222222" "0000", CYCLONE_PREFIX, FAST_DDS_PREFIX)
    writers = [Writer(prefix) for prefix in (ours, talker, listener)]
    talker_pub, listener_sub, our_sub = talker + "00000103", listener + "00000104", ours + "00000704"
    told = {bytes.fromhex(ours): _told(["_roc_1"], [our_sub]), bytes.fromhex(talker): _told(["talker"], [talker_pub]),
            bytes.fromhex(listener): _told(["listener"], [listener_sub])}
    nodes = {("/", "talker"), ("/", "listener"), ("/", "_roc_1")}
    endpoints = {bytes.fromhex(gid) for gid in (talker_pub, listener_sub, our_sub)}
    assert incomplete_participants(writers, told, endpoints, nodes) == 0
    # the listener's subscription is told but not discovered yet: only the listener is incomplete
    assert incomplete_participants(writers, told, endpoints - {bytes.fromhex(listener_sub)}, nodes) == 1
    # a node told that the graph does not show yet
    assert incomplete_participants(writers, told, endpoints, nodes - {("/", "talker")}) == 1
    # no message from the listener yet; nor this process's own
    assert incomplete_participants(writers, {bytes.fromhex(talker): told[bytes.fromhex(talker)]}, endpoints, nodes) == 2
    assert incomplete_participants(writers, {}, set(), set()) == 3


def test_a_participant_of_roc_s_own_nodes_only_is_complete_once_its_message_has_come() -> None:
    """roc's daemon on Cyclone DDS: rmw_cyclonedds 2.2.2 leaves a destroyed subscription listed in its
    participant's message (ros2/rmw_cyclonedds#594), so the reader of the daemon's first wait stays told
    and is never discovered. roc leaves its own nodes out of every answer: such a participant is not
    waited for once its message has come; any other participant's told reader still is."""
    daemon, listener = "0110" "3333bbbb" "44444444" "0000", FAST_DDS_PREFIX
    writers = [Writer(prefix) for prefix in (daemon, listener)]
    gone, listener_sub = daemon + "00000704", listener + "00000104"
    told = {bytes.fromhex(daemon): _told(["_roc_7"], [gone]), bytes.fromhex(listener): _told(["listener"], [listener_sub])}
    nodes = {("/", "_roc_7"), ("/", "listener")}
    assert incomplete_participants(writers, told, {bytes.fromhex(listener_sub)}, nodes) == 0
    assert incomplete_participants(writers, told, set(), nodes) == 1  # the listener's reader is waited for
    assert incomplete_participants(writers, {}, set(), set()) == 2  # no message yet: whose it is is not known
    # a roc bridge's node is no node of roc's own: its participant is waited for
    bridge = {**told, bytes.fromhex(daemon): _told(["_roc_bridge_7"], [gone])}
    assert incomplete_participants(writers, bridge, {bytes.fromhex(listener_sub)}, nodes | {("/", "_roc_bridge_7")}) == 1


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


def test_the_probe_hears_the_guid_prefix_of_each_participant_of_this_host_that_answers(tmp_path: Path) -> None:
    """Domain 202, above the tests' domains: a socket standing in for another process's participant gets
    the stand-in's announcement, whose locator is the probe's, and answers there as any participant
    does; the probe names it by the GUID prefix of the answer's RTPS header. A message that holds no
    announcement is no answer."""
    [theirs] = _bound_at_free_participant_ports(202, 1)
    table = tmp_path / "udp"
    port = theirs.getsockname()[1]
    table.write_text(UDP_HEADER + "".join(_udp_line(port + offset, "99", "0100007F") for offset in (0, 1)))
    probe = LocalParticipantProbe(202, (table,))
    try:
        assert probe.heard() == set()
        assert probe.ask() == 1
        assert probe.ask_again() == 0  # asked just now
        theirs.settimeout(5)
        asked = theirs.recv(65536)
        at = asked.index(struct.pack("<HH", 0x0032, 24)) + 4  # PID_METATRAFFIC_UNICAST_LOCATOR
        probe_port, probe_address = struct.unpack("<I", asked[at + 4:at + 8])[0], socket.inet_ntoa(asked[at + 20:at + 24])
        announcement = _submessage(0x15, SPDP_WRITER.join([bytes(8), bytes(40)]))  # a DATA of its announcer
        answer = b"RTPS\x02\x03\x01\x10" + bytes.fromhex(CYCLONE_PREFIX) + announcement
        not_an_answer = b"RTPS\x02\x03\x01\x0f" + bytes.fromhex(FAST_DDS_PREFIX) + _heartbeat(SEDP_PUBLICATIONS[1], 1, 2)
        for message in (not_an_answer, answer, b"not RTPS at all"):
            theirs.sendto(message, (probe_address, probe_port))
        for _ in range(100):
            if probe.heard():
                break
            time.sleep(0.05)
        assert probe.heard() == {bytes.fromhex(CYCLONE_PREFIX)}
    finally:
        probe.close()
        theirs.close()
    unreadable = LocalParticipantProbe(202, (tmp_path / "missing",))
    assert unreadable.ask() == 0  # not Linux
    unreadable.close()


def _submessage(kind: int, body: bytes) -> bytes:
    return struct.pack("<BBH", kind, 0x01, len(body)) + body  # little endian


def test_an_rtps_message_is_undirected_by_leaving_out_its_info_dst() -> None:
    header = b"RTPS\x02\x01\x01\x10" + bytes.fromhex(CYCLONE_PREFIX)
    data = _submessage(0x15, bytes(40))  # a DATA
    info_ts, invalid_ts = _submessage(0x09, bytes(8)), struct.pack("<BBH", 0x09, 0x03, 0)  # a time, none (length 0)
    info_dst = _submessage(0x0E, bytes.fromhex("28ef312b86f1396505bf5ca0"))
    assert undirected(header + info_dst + info_ts + data) == header + info_ts + data
    assert undirected(header + invalid_ts + info_dst + data) == header + invalid_ts + data
    assert undirected(header + info_ts + data) is None  # for anyone already
    assert undirected(b"not RTPS at all") is None


def test_the_probe_passes_an_answer_directed_to_the_stand_in_on_undirected_to_this_process_s_participants(
        tmp_path: Path) -> None:
    """Domain 203, above the tests' domains: Cyclone DDS answers the stand-in with an announcement whose
    INFO_DST names the stand-in, which a Fast DDS participant of this process ignores, and Cyclone
    answers no participant twice; the probe sends its first answer on to this process's participant
    (a socket of this process at a participant's ports), without the INFO_DST; an undirected answer
    (Fast DDS's) is not sent on."""
    ours, theirs = _bound_at_free_participant_ports(203, 2)
    table = tmp_path / "udp"
    own_inode = str(os.fstat(ours.fileno()).st_ino)  # a socket's inode, as /proc/net/udp names it
    table.write_text(UDP_HEADER + "".join(_udp_line(sock.getsockname()[1] + offset, inode, "0100007F")
                                          for sock, inode in ((ours, own_inode), (theirs, "99")) for offset in (0, 1)))
    probe = LocalParticipantProbe(203, (table,))
    try:
        assert probe.ask() == 1
        theirs.settimeout(5)
        asked = theirs.recv(65536)
        at = asked.index(struct.pack("<HH", 0x0032, 24)) + 4  # PID_METATRAFFIC_UNICAST_LOCATOR
        probe_at = (socket.inet_ntoa(asked[at + 20:at + 24]), struct.unpack("<I", asked[at + 4:at + 8])[0])
        announcement = _submessage(0x09, bytes(8)) + _submessage(0x15, SPDP_WRITER.join([bytes(8), bytes(40)]))
        header = b"RTPS\x02\x01\x01\x10" + bytes.fromhex(CYCLONE_PREFIX)
        theirs.sendto(header + _submessage(0x0E, asked[8:20]) + announcement, probe_at)  # to the stand-in
        theirs.sendto(b"RTPS\x02\x03\x01\x0f" + bytes.fromhex(FAST_DDS_PREFIX) + announcement, probe_at)
        for _ in range(100):
            if len(probe.heard()) == 2:
                break
            time.sleep(0.05)
        assert probe.heard() == {bytes.fromhex(CYCLONE_PREFIX), bytes.fromhex(FAST_DDS_PREFIX)}
        ours.settimeout(5)
        assert ours.recv(65536) == header + announcement
        ours.settimeout(0.2)
        with pytest.raises(socket.timeout):  # the Fast DDS answer was for anyone already
            ours.recv(65536)
    finally:
        probe.close()
        ours.close()
        theirs.close()


def _heartbeat(writer: bytes, first: int, last: int, count: int = 1) -> bytes:
    return _submessage(0x07, bytes(4) + writer + struct.pack("<iIiII", 0, first, 0, last, count))


def _data(writer: bytes, number: int, payload: bytes = bytes(8)) -> bytes:
    return _submessage(0x15, struct.pack("<HH", 0, 16) + bytes(4) + writer + struct.pack("<iI", 0, number) + payload)


def test_heartbeats_and_data_are_read_with_whom_they_are_for() -> None:
    stand_in, writer = bytes(range(12)), SEDP_PUBLICATIONS[1]
    message = b"RTPS\x02\x03\x01\x0f" + bytes.fromhex(FAST_DDS_PREFIX) + _submessage(0x0E, stand_in) \
        + _data(writer, 4) + _heartbeat(writer, 1, 5)
    assert heartbeats(message) == [(stand_in, writer, 1, 5)]
    assert data_sequence_numbers(message) == [(writer, 4)]
    assert heartbeats(message[:-4]) == []  # cut short
    undirected_heartbeat = b"RTPS\x02\x03\x01\x0f" + bytes.fromhex(FAST_DDS_PREFIX) + _heartbeat(writer, 2, 3)
    assert heartbeats(undirected_heartbeat) == [(b"", writer, 2, 3)]


def test_an_acknack_request_asks_for_each_sequence_number_of_a_range_or_for_none() -> None:
    reader, writer = SEDP_PUBLICATIONS
    message = acknack_request(bytes(12), bytes(range(12)), reader, writer, 3, 36, 7)
    acknack = message[36:]  # after the header (20) and INFO_DST (16)
    assert acknack[:4] == struct.pack("<BBH", 0x06, 0x01, len(acknack) - 4)
    assert acknack[4:12] == reader + writer
    base_high, base_low, bits, first_word, second_word, count = struct.unpack_from("<iIIIII", acknack, 12)
    assert (base_high << 32 | base_low, bits, count) == (3, 34, 7)
    assert (first_word, second_word) == (0xFFFFFFFF, 0xC0000000)  # 34 bits, the first one the highest
    none = acknack_request(bytes(12), bytes(range(12)), reader, writer, 6, 5, 8)[36:]
    assert struct.unpack_from("<iIII", none, 12) == (0, 6, 0, 8)  # everything before 6, nothing asked


def test_a_fetch_asks_each_writer_for_what_it_lacks_once_it_knows_where_and_passes_each_message_on_a_few_times(
        ) -> None:
    fetch, stand_in, writer = EndpointFetch(), bytes(range(12)), SEDP_SUBSCRIPTIONS[1]
    fetch.stand_ins.add(stand_in)
    participant, at = bytes.fromhex(FAST_DDS_PREFIX), ("127.0.0.1", 7412)
    header = b"RTPS\x02\x03\x01\x0f" + participant
    to_stand_in = _submessage(0x0E, stand_in)
    assert fetch.take(participant, header + to_stand_in + _heartbeat(writer, 1, 3), []) == []  # not where yet
    [(request, address)] = fetch.take(participant, header, [at])
    assert (request, address) == (acknack_request(stand_in, participant, SEDP_SUBSCRIPTIONS[0], writer, 1, 3, 1), at)
    brought = header + to_stand_in + _data(writer, 2)
    assert fetch.take(participant, brought, [at]) == []
    [(request, _)] = fetch.take(participant, header + to_stand_in + _heartbeat(writer, 1, 3), [at])
    assert request == acknack_request(stand_in, participant, SEDP_SUBSCRIPTIONS[0], writer, 1, 3, 2)  # 1 and 3 missing
    for number in (1, 3):
        fetch.take(participant, header + to_stand_in + _data(writer, number), [at])
    [(request, _)] = fetch.take(participant, header + to_stand_in + _heartbeat(writer, 1, 3), [at])
    assert request == acknack_request(stand_in, participant, SEDP_SUBSCRIPTIONS[0], writer, 4, 3, 3)  # all there
    other = bytes(range(1, 13))  # a HEARTBEAT for another participant's reader is not answered
    assert fetch.take(participant, header + _submessage(0x0E, other) + _heartbeat(writer, 1, 3), [at]) == []
    cyclone = bytes.fromhex(CYCLONE_PREFIX)  # its writers answer at once: acknowledged, nothing kept
    from_cyclone = b"RTPS\x02\x01\x01\x10" + cyclone + to_stand_in + _data(writer, 1) + _heartbeat(writer, 1, 2)
    [(request, _)] = fetch.take(cyclone, from_cyclone, [at])
    assert request == acknack_request(stand_in, cyclone, SEDP_SUBSCRIPTIONS[0], writer, 3, 2, 1)
    passed = [fetch.to_pass_on() for _ in range(PASS_ON_TIMES + 1)]
    assert all(len(messages) == 3 for messages in passed[:-1]) and passed[-1] == []
    assert undirected(brought) in passed[0]  # without the INFO_DST that named the stand-in
    assert fetch.asked_all(1) and not fetch.asked_all(2)  # two writers asked: as many as one participant has


def _announcement(prefix: bytes, metatraffic: tuple[str, int], default: tuple[str, int]) -> bytes:
    """An RTPS message holding a participant announcement (SPDP DATA, PL_CDR_LE) with these unicast
    locators, as a participant answers the stand-in's."""
    def locator(pid: int, address: tuple[str, int]) -> bytes:
        return struct.pack("<HHiI", pid, 24, 1, address[1]) + bytes(12) + socket.inet_aton(address[0])
    parameters = locator(0x0032, metatraffic) + locator(0x0031, default) + struct.pack("<HH", 0x0001, 0)
    data = struct.pack("<HH", 0, 16) + bytes.fromhex("000100c7") + SPDP_WRITER + struct.pack("<iI", 0, 1) \
        + b"\x00\x03\x00\x00" + parameters
    return b"RTPS\x02\x03\x01\x0f" + prefix + _submessage(0x09, bytes(8)) + _submessage(0x15, data)


def test_an_announcement_tells_where_its_participant_takes_discovery_traffic_and_its_endpoints_traffic() -> None:
    answer = _announcement(bytes.fromhex(FAST_DDS_PREFIX), ("192.0.2.2", 7412), ("192.0.2.2", 7413))
    assert announced_locators(answer) == [("192.0.2.2", 7412)]
    assert announced_locators(answer, PID_DEFAULT_UNICAST_LOCATOR) == [("192.0.2.2", 7413)]
    stand_in = stand_in_announcement(5, [("127.0.0.1", 7412), ("127.0.0.1", 7414)])
    assert announced_locators(stand_in) == announced_locators(stand_in, PID_DEFAULT_UNICAST_LOCATOR) \
        == [("127.0.0.1", 7412), ("127.0.0.1", 7414)]
    assert announced_locators(answer[:-40]) == []  # cut short
    assert announced_locators(b"RTPS" + bytes(30)) == announced_locators(b"not RTPS at all") == []


def test_an_acknack_prompt_is_a_reader_s_first_acknack_to_each_writer_numbered_as_asked() -> None:
    """What a Fast DDS reader sends first (an empty set of sequence numbers from 0, not final), for each
    (reader, writer) pair, from the reader's participant (the header) to the writer's (INFO_DST)."""
    reader, writer = bytes.fromhex(CYCLONE_PREFIX), bytes.fromhex(FAST_DDS_PREFIX)
    discovery_info = (bytes.fromhex("00000504"), bytes.fromhex("00000103"))
    message = acknack_prompt(reader, writer, [SEDP_PUBLICATIONS, discovery_info], 0xFFFFFFFF)
    assert message[:20] == b"RTPS\x02\x03\x00\x00" + reader
    assert message[20:36] == _submessage(0x0E, writer)
    acknacks = [message[36 + 28 * i:36 + 28 * (i + 1)] for i in range(2)]
    assert len(message) == 36 + 28 * 2
    for acknack, (reader_id, writer_id) in zip(acknacks, [SEDP_PUBLICATIONS, discovery_info]):
        assert acknack[:4] == bytes([0x06, 0x01, 24, 0])  # ACKNACK, little endian, not final
        assert acknack[4:12] == reader_id + writer_id
        assert struct.unpack("<iIII", acknack[12:]) == (0, 0, 0, 0xFFFFFFFF)  # base 0, no bits, the count
    assert [is_builtin(writer_id) for _, writer_id in (SEDP_PUBLICATIONS, SEDP_SUBSCRIPTIONS, discovery_info)] \
        == [True, True, False]


def test_the_writers_prompted_are_those_of_this_host_s_participants_whose_message_has_not_come() -> None:
    """Their endpoint discovery writers first; their ros_discovery_info writer, for each of this process's
    readers of the topic, once discovered. Participants of other hosts (not heard) and this process's own
    are never prompted."""
    own, fast, told_fast = (bytes.fromhex(p) for p in (CYCLONE_PREFIX, FAST_DDS_PREFIX, "010f" + "cd" * 10))
    told = {own: _told(["_roc_42"], []), told_fast: _told(["talker"], [])}
    assert own_participant(told, "_roc_42") == own
    assert own_participant({told_fast: told[told_fast]}, "_roc_42") is None  # its own message not come yet

    def endpoint(prefix: bytes, entity: str) -> Writer:
        found = Writer(prefix.hex())
        found.endpoint_gid = list(prefix + bytes.fromhex(entity))
        return found
    readers = [endpoint(own, "00000504"), endpoint(own, "00000704"), endpoint(fast, "00000204")]
    sedp = [SEDP_PUBLICATIONS, SEDP_SUBSCRIPTIONS]
    assert writers_to_prompt(own, {own, fast, told_fast}, told, [], readers) == {fast: sedp}
    writers = [endpoint(fast, "00000103"), endpoint(told_fast, "00000103")]
    assert writers_to_prompt(own, {own, fast, told_fast}, told, writers, readers) == {fast: [
        *sedp, (bytes.fromhex("00000504"), bytes.fromhex("00000103")),
        (bytes.fromhex("00000704"), bytes.fromhex("00000103"))]}
    assert writers_to_prompt(own, {own, told_fast}, told, writers, readers) == {}
    # the vendors: Cyclone DDS loses early HEARTBEATs, Fast DDS writers take a prompt whose count wraps
    cyclone, fast_dds = vendors.of_prefix(own), vendors.of_prefix(fast)
    assert cyclone.loses_early_heartbeats and cyclone.prompt_count is None
    assert not fast_dds.loses_early_heartbeats and (fast_dds.prompt_count + 1) % 2 ** 32 == 0


def test_the_probe_prompts_a_participant_that_answered_discovery_writers_at_its_metatraffic_port_others_at_its_default_one(
        tmp_path: Path) -> None:
    """Domain 204, above the tests' domains: a Fast DDS writer takes an ACKNACK only on the port it listens
    on for that endpoint (roc.ros.vendors.fastdds)."""
    [metatraffic] = _bound_at_free_participant_ports(204, 1)
    default = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    default.bind(("127.0.0.1", metatraffic.getsockname()[1] + 1))
    table = tmp_path / "udp"
    table.write_text(UDP_HEADER + "".join(_udp_line(sock.getsockname()[1], "99", "0100007F")
                                          for sock in (metatraffic, default)))
    own, fast = bytes.fromhex(CYCLONE_PREFIX), bytes.fromhex(FAST_DDS_PREFIX)
    discovery_info = (bytes.fromhex("00000504"), bytes.fromhex("00000103"))
    probe = LocalParticipantProbe(204, (table,))
    try:
        assert not probe.prompt(own, fast, [SEDP_PUBLICATIONS], 0xFFFFFFFF)  # it has not answered
        assert probe.ask() == 1
        metatraffic.settimeout(5)
        asked = metatraffic.recv(65536)
        at = asked.index(struct.pack("<HH", 0x0032, 24)) + 4  # PID_METATRAFFIC_UNICAST_LOCATOR
        probe_at = (socket.inet_ntoa(asked[at + 20:at + 24]), struct.unpack("<I", asked[at + 4:at + 8])[0])
        metatraffic.sendto(_announcement(fast, metatraffic.getsockname(), default.getsockname()), probe_at)
        for _ in range(100):
            if probe.heard():
                break
            time.sleep(0.05)
        assert probe.prompt(own, fast, [SEDP_PUBLICATIONS, SEDP_SUBSCRIPTIONS, discovery_info], 0xFFFFFFFF)
        default.settimeout(5)
        assert metatraffic.recv(65536) == acknack_prompt(own, fast, [SEDP_PUBLICATIONS, SEDP_SUBSCRIPTIONS],
                                                         0xFFFFFFFF)
        assert default.recv(65536) == acknack_prompt(own, fast, [discovery_info], 0xFFFFFFFF)
        assert not probe.prompt(own, fast, [SEDP_PUBLICATIONS, SEDP_SUBSCRIPTIONS, discovery_info], 0xFFFFFFFF)
        assert probe.prompt(own, fast, [SEDP_PUBLICATIONS], 0xFFFFFFFF)  # another prompt goes at once
    finally:
        probe.close()
        metatraffic.close()
        default.close()


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


@pytest.mark.slow  # a node of its own (the quick loop stays under 45 s)
def test_a_fetching_probe_gets_a_real_participant_s_endpoints_and_passes_them_on_whole(tmp_path: Path) -> None:
    """The suite's middleware offers the fetching stand-in its endpoints, and sends their announcements
    when asked; the probe passes each message on, whole and undirected, to this process's participant
    (sockets of this process at a participant's two ports)."""
    env = graph_env(SLOT, tmp_path)
    [node] = start_nodes([{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}], env)
    domain = int(env["ROS_DOMAIN_ID"])
    ours = []
    for participant in range(100, 120):  # ids no participant of the node takes: it takes the lowest free one
        port = 7400 + 250 * domain + 10 + 2 * participant
        try:
            ours = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(2)]
            for offset, sock in enumerate(ours):
                sock.bind(("127.0.0.1", port + offset))
            break
        except OSError:
            for sock in ours:
                sock.close()
    probe = LocalParticipantProbe(domain, fetches_endpoints=True)
    try:
        assert probe.ask() == 1
        ours[0].settimeout(0.05)
        received: list[bytes] = []
        deadline = time.monotonic() + 20
        while not any(b"rt/chatter" in message for message in received) and time.monotonic() < deadline:
            probe.pass_on_endpoints()
            with contextlib.suppress(socket.timeout):
                received.append(ours[0].recv(65536))
        [announcement] = [message for message in received if b"rt/chatter" in message]
        assert announcement[8:20] in probe.heard()  # from the node's participant, as its writer sent it
        assert undirected(announcement) is None  # for whoever takes it
        assert (SEDP_PUBLICATIONS[1], 1) <= max(data_sequence_numbers(announcement))
    finally:
        probe.close()
        for sock in ours:
            sock.close()
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


def test_a_discovery_message_is_read_from_its_cdr_as_rclpy_reads_it() -> None:
    """rclpy's serialization of rmw_dds_common's message is the oracle for roc's reading of its CDR
    (roc.ros.discovery_info.told_by, which needs neither the message's Python class nor numpy)."""
    from rclpy.serialization import serialize_message
    from rmw_dds_common.msg import Gid, NodeEntitiesInfo, ParticipantEntitiesInfo

    from roc.ros.discovery_info import told_by

    def gid(first: int) -> Gid:
        return Gid(data=list(range(first, first + 16)))

    nodes = [NodeEntitiesInfo(node_namespace="/", node_name="talker", reader_gid_seq=[gid(1)],
                              writer_gid_seq=[gid(2), gid(3)]),
             NodeEntitiesInfo(node_namespace="/robot1", node_name="odom_pub", reader_gid_seq=[],
                              writer_gid_seq=[gid(4)])]
    cdr = serialize_message(ParticipantEntitiesInfo(gid=gid(100), node_entities_info_seq=nodes))
    prefix, told = told_by(cdr)
    assert prefix == bytes(range(100, 112))
    assert told.nodes == {("/", "talker"), ("/robot1", "odom_pub")}
    assert told.endpoints == {bytes(range(first, first + 16)) for first in (1, 2, 3, 4)}
    assert told_by(serialize_message(ParticipantEntitiesInfo(gid=gid(7))))[1] == Told(frozenset(), frozenset())
    with pytest.raises(RocError, match="ros_discovery_info message ends early"):
        told_by(cdr[:-5])


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


# In a process of its own: a first query's wait (the default period), why it ended, and the nodes it saw
FIRST_QUERY = """
import json
from roc.ros.graph import Graph

graph = Graph()
why = graph.wait_for_discovery()
nodes = sorted(name for name, _ in graph.node.get_node_names_and_namespaces())
graph.close()
print(json.dumps({"why": why, "nodes": nodes}))
"""
TALKER = {"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}
LISTENER = {"name": "listener", "subscribers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}


@pytest.mark.slow
@pytest.mark.rmw
def test_a_first_query_on_the_suite_s_middleware_ends_because_the_graph_is_complete(tmp_path: Path) -> None:
    """On Cyclone DDS (the middleware suite) as on Fast DDS: the wait ends once both processes are wholly
    known, not when its period runs out (Cyclone's message info and GUIDs are not Fast DDS's)."""
    if suite_middleware() == CYCLONEDDS:
        require_cyclonedds()
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([TALKER, LISTENER], env)
    try:
        seen = _printed_by(FIRST_QUERY, process_environment(env))
    finally:
        stop_all(processes)
    assert seen["why"] == "complete"
    assert {"talker", "listener"} <= set(seen["nodes"])


@pytest.mark.slow
@pytest.mark.rmw
def test_a_first_query_beside_roc_s_daemon_ends_because_the_graph_is_complete(tmp_path: Path) -> None:
    """On Cyclone DDS the daemon's participant lists the reader of its first wait after it was destroyed
    (rmw_cyclonedds 2.2.2): a first query beside the daemon waited out its period (3.5 s, "incomplete")."""
    if suite_middleware() == CYCLONEDDS:
        require_cyclonedds()
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([TALKER], env)
    try:
        started = roc("daemon", "start", env=env)
        assert started.returncode == 0, started.stderr
        listed = roc("node", "list", env=env)  # answered once the daemon's first wait has ended
        assert "/talker" in listed.stdout.split(), listed.stderr
        seen = _printed_by(FIRST_QUERY, process_environment(env))
    finally:
        roc("daemon", "stop", env=env)
        stop_all(processes)
    assert seen["why"] == "complete"
    assert "talker" in seen["nodes"]


@pytest.mark.slow
@pytest.mark.rmw
@pytest.mark.xdist_group("busy_or_timing")  # its bound is Fast DDS's heartbeat period (see scripts/test.sh)
def test_a_cyclone_dds_first_query_beside_fast_dds_processes_is_complete_before_their_writers_next_heartbeat(
        tmp_path: Path) -> None:
    """A fresh Cyclone DDS participant drops the first HEARTBEATs of the Fast DDS participants that answer it,
    and their writers sent the next only a period later (1 s for their endpoints, 3 s for their
    ros_discovery_info): a first query took 2.2 to 3.4 s. roc prompts those writers, so the wait is
    complete within Fast DDS's endpoint discovery period, 1 s, with time to spare."""
    require_cyclonedds()
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([TALKER, LISTENER], on_middleware(env, FASTRTPS))
    try:
        seen = _printed_by(FIRST_QUERY.replace("wait_for_discovery()", "wait_for_discovery(period=0.9)"),
                           process_environment(on_middleware(env, CYCLONEDDS)))
    finally:
        stop_all(processes)
    assert seen["why"] == "complete"
    assert {"talker", "listener"} <= set(seen["nodes"])


@pytest.mark.slow
def test_a_fast_dds_first_query_beside_a_cyclone_dds_process_ends_because_the_graph_is_complete(
        tmp_path: Path) -> None:
    """A mixed domain: a Cyclone DDS talker and a Fast DDS listener. A first query on Fast DDS ends once both
    are wholly known (the Cyclone process made it wait until its period ran out: 6.5 s)."""
    require_cyclonedds()
    env = graph_env(SLOT, tmp_path)
    processes = [*start_nodes([TALKER], on_middleware(env, CYCLONEDDS)),
                 *start_nodes([LISTENER], on_middleware(env, FASTRTPS))]
    try:
        seen = _printed_by(FIRST_QUERY, process_environment(on_middleware(env, FASTRTPS)))
    finally:
        stop_all(processes)
    assert seen["why"] == "complete"
    assert {"talker", "listener"} <= set(seen["nodes"])
