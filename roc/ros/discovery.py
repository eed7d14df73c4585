"""How many participants a fresh participant must discover before its graph is complete, so that a
first query answers as soon as it has seen everything instead of after a fixed wait. Nothing here
assumes a DDS vendor's GUID layout (what differs between vendors: roc.ros.vendors); it holds for every
RTPS vendor:
- every participant binds the metatraffic unicast UDP port its domain and participant id give
  (RTPS 9.6.1.1: 7400 + 250 * domain + 10 + 2 * id) and the user-data port above it (Fast DDS, and
  Cyclone DDS on the LOCALHOST and SUBNET ranges), so ``/proc/net/udp`` tells how many participants
  this host has in a domain, whether or not they have been heard yet;
- every participant answers a participant new to it with its own announcement at once, and an RTPS
  message's header names its sender's GUID prefix, so the answers to a stand-in's announcement sent to
  those ports name this host's participants (``LocalParticipantProbe``, which passes an answer directed
  to the stand-in on to this process's participants: Cyclone DDS directs its answers, roc.ros.spdp.
  undirected);
- a participant's endpoints share its GUID prefix, and every ROS participant has one writer on
  ``ros_discovery_info`` (rmw_dds_common), so the writers discovered tell which of this host's
  participants have been discovered (``local_peers_discovered``).

A participant discovered is not wholly known yet: its nodes come in its ``ros_discovery_info`` message
(under load 0.1 s and more after its writer), and each endpoint in an announcement of its own, which
may come later still. It is once its message has come and every node and endpoint GID the message
lists has been discovered (``incomplete_participants``; the message is read by
roc.ros.discovery_info, and names its participant's GUID).

A fresh Fast DDS participant's first announcement goes out before it listens, so it would hear some of
them only at their next periodic announcement: it asks them to announce themselves again
(``ask_local_participants_to_announce``, roc.ros.spdp), with input buffers large enough for all their
answers at once (``enlarge_input_buffers``).

A fresh Cyclone DDS participant drops the first HEARTBEATs of the participants that answer it, so it
would hear a Fast DDS participant's endpoints and ``ros_discovery_info`` only at that writer's next
periodic HEARTBEAT (roc.ros.vendors.cyclonedds): the probe prompts them, by the GUID prefixes and
locators they answered with, to send one at once (``writers_to_prompt``, ``LocalParticipantProbe.prompt``).

A Fast DDS writer of endpoint announcements answers a request 0.1 s after it comes, so a query without
the daemon asks them before its participant exists, while rclpy loads, and passes what they send on to
that participant (``early_probe``, ``EndpointFetch``).

Participants on other hosts (a discovery range beyond this host) cannot be counted: the caller waits
for the graph to go quiet for them. This module reads /proc and rclpy endpoint infos and sends UDP
datagrams; it never imports rclpy itself (``roc tui`` finds each node's process with it too).
"""

from __future__ import annotations

import contextlib
import os
import socket
import time
from collections.abc import Container, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from roc.ros import vendors
from roc.ros.protocol import is_own_node, middleware
from roc.ros.spdp import (
    GUID_PREFIX_BYTES,
    MAX_REQUESTED,
    PID_DEFAULT_UNICAST_LOCATOR,
    RTPS_HEADER_BYTES,
    SEDP_PUBLICATIONS,
    SEDP_SUBSCRIPTIONS,
    SPDP_WRITER,
    acknack_prompt,
    acknack_request,
    announced_locators,
    announced_properties,
    data_sequence_numbers,
    heartbeats,
    is_builtin,
    stand_in_announcement,
    undirected,
)

PORT_BASE = 7400
DOMAIN_GAIN = 250
PARTICIPANT_GAIN = 2
METATRAFFIC_UNICAST_OFFSET = 10
USER_PORT_OFFSET = 1  # a participant's user-data unicast port, above its metatraffic one (RTPS 9.6.1.1)
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"  # rmw_dds_common's name for the node of an endpoint not told yet
MAX_PARTICIPANT_ID = 119  # the highest id whose ports stay within the domain's 250
DISCOVERY_TOPIC = "ros_discovery_info"  # a DDS name, outside ROS's conventions (no rt/ prefix)
UDP_TABLES = (Path("/proc/net/udp"), Path("/proc/net/udp6"))
ENTITY_ID = slice(GUID_PREFIX_BYTES, GUID_PREFIX_BYTES + 4)  # of a GUID (an endpoint GID): after its prefix
ASK_AGAIN_SECONDS = 0.5  # LocalParticipantProbe.ask_again: at most this often
PROMPT_AGAIN_SECONDS = 0.2  # LocalParticipantProbe.prompt: the same prompt to a participant at most this often
EARLY_ANSWER_SECONDS = 0.02  # early_probe: at most this long for the participants' answers and HEARTBEATs
PASS_ON_TIMES = 3  # EndpointFetch.to_pass_on: each message at most this often (one that comes too early is dropped)
MAX_REQUESTS = 3  # EndpointFetch: requests to one writer at most, then every HEARTBEAT is acknowledged
# the writers of endpoint announcements (RTPS 9.3.1.3), each with its reader: a fetching stand-in's
ENDPOINT_READERS = {SEDP_PUBLICATIONS[1]: SEDP_PUBLICATIONS[0], SEDP_SUBSCRIPTIONS[1]: SEDP_SUBSCRIPTIONS[0]}
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


def participant_prefix(gid: bytes) -> bytes:
    """The GUID prefix of the participant of an endpoint or participant GID (RTPS 8.2.4: a participant's
    endpoints share its 12-byte prefix; rmw's GIDs of a DDS middleware are those GUIDs)."""
    return gid[:GUID_PREFIX_BYTES]


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


def _peer_addresses(sockets: list[tuple[str | None, int, bool]], own: bool) -> list[tuple[str, int]]:
    """Where to send to the IPv4 ``sockets`` of metatraffic_sockets, this process's own or the others'."""
    return sorted({(_reachable(address), port) for address, port, ours in sockets if ours == own and address})


def _send_stand_in(domain_id: int, locators: list[tuple[str, int]], peers: list[tuple[str, int]],
                   prefix: bytes | None = None, fetches_endpoints: bool = False) -> int:
    """Send each of ``peers`` the announcement of a stand-in participant of ``domain_id`` whose locators
    are ``locators`` (roc.ros.spdp.stand_in_announcement); returns to how many it went."""
    message = stand_in_announcement(domain_id, locators, prefix, fetches_endpoints)
    asked = 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        for peer in peers:
            try:
                sender.sendto(message, peer)
                asked += 1
            except OSError:  # gone meanwhile, or a full buffer: that one is heard at its next announcement
                continue
    return asked


def ask_local_participants_to_announce(domain_id: int, tables: tuple[Path, ...] = UDP_TABLES) -> int:
    """Send every participant of another process on this host in ``domain_id`` the announcement of a
    stand-in participant whose locators are this process's participants' discovery ports, so that each
    announces itself to them at once (why: roc.ros.spdp). Returns how many were asked (0 where the UDP
    tables cannot be read)."""
    try:
        sockets = metatraffic_sockets(domain_id, tables)
    except (OSError, IndexError, ValueError):
        return 0
    ours, peers = _peer_addresses(sockets, own=True), _peer_addresses(sockets, own=False)
    if not ours or not peers:
        return 0
    return _send_stand_in(domain_id, ours, peers)


class LocalParticipantProbe:
    """Which participants of other processes on this host are in a domain, by their GUID prefixes: ``ask``
    sends each of them the announcement of a stand-in participant whose one locator is a socket of the
    probe's own; each answers at once with its own announcement, whose RTPS header names its GUID prefix
    (``heard``). Any RTPS vendor's participant answers so (Fast DDS and Cyclone DDS measured: within
    5 ms), and no vendor's GUID layout is read. The first answer of each that was directed to the
    stand-in (Cyclone DDS's) goes on, undirected, to this process's participants in the domain
    (roc.ros.spdp.undirected: a Fast DDS participant beside a Cyclone one otherwise heard it up to 1 s
    later, in 1 to 5 of 8 first queries here). ``prompt`` asks the writers of a participant that answered
    for a HEARTBEAT, at the locators of its answer.

    ``fetches_endpoints``: its first stand-in also reads endpoint announcements, so every participant
    offers it its endpoints, and the probe asks each writer of them whose vendor answers such a request
    late (Fast DDS: 0.1 s after it comes, roc.ros.vendors.fastdds) for all its HEARTBEAT says it has
    (EndpointFetch); a writer that answers at once gets an acknowledgement of all it has instead.
    Made before this process's participant (early_probe), it has their announcements by the time that
    participant exists, and ``pass_on_endpoints`` gives the messages to it whole: they come from their
    writer, to a reader that knows that writer, and each participant takes them as if sent to it. A
    first query of a Cyclone DDS participant beside three Fast DDS processes took 0.36 s with it and
    0.45 s without (12 runs each), beside three Cyclone DDS processes 0.35 s either way."""

    def __init__(self, domain_id: int, tables: tuple[Path, ...] = UDP_TABLES, fetches_endpoints: bool = False) -> None:
        self.domain_id = domain_id
        self.tables = tables
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._socket.bind(("127.0.0.1", 0))
        self._heard: dict[bytes, dict[str, str]] = {}  # GUID prefix -> the properties it announced
        self._asked_at: float | None = None
        self._ours: list[tuple[str, int]] = []  # this process's participants' discovery ports
        # GUID prefix -> the locators it announced: of its discovery traffic, of its endpoints'
        self._locators: dict[bytes, tuple[list[tuple[str, int]], list[tuple[str, int]]]] = {}
        # (GUID prefix, the endpoints prompted) -> when (prompt)
        self._prompted_at: dict[tuple[bytes, tuple[tuple[bytes, bytes], ...]], float] = {}
        self._fetcher = EndpointFetch() if fetches_endpoints else None
        self._asked = 0  # participants the last ask went to
        if self._fetcher is not None:  # what they send waits here while rclpy loads
            with contextlib.suppress(OSError):
                self._socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, INPUT_BUFFER_BYTES)
        self._socket.setblocking(False)

    def ask(self) -> int:
        """Ask every participant of another process on this host to announce itself to the probe; returns
        how many were asked (0 where the UDP tables cannot be read)."""
        self._asked_at = time.monotonic()
        try:
            sockets = metatraffic_sockets(self.domain_id, self.tables)
        except (OSError, IndexError, ValueError):
            return 0
        peers, self._ours = _peer_addresses(sockets, own=False), _peer_addresses(sockets, own=True)
        if not peers:
            return 0
        prefix = os.urandom(GUID_PREFIX_BYTES)
        fetcher = self._fetcher if self._fetcher is not None and not self._fetcher.stand_ins else None
        if fetcher is not None:  # the first stand-in only: a later one would be offered it all again
            fetcher.stand_ins.add(prefix)
        self._asked = _send_stand_in(self.domain_id, [self._socket.getsockname()], peers, prefix,
                                     fetcher is not None)
        return self._asked

    def ask_again(self) -> int:
        """``ask`` if the last was ASK_AGAIN_SECONDS ago or more (else 0)."""
        if self._asked_at is not None and time.monotonic() - self._asked_at < ASK_AGAIN_SECONDS:
            return 0
        return self.ask()

    def heard(self) -> set[bytes]:
        """The GUID prefixes of the participants that answered so far."""
        return set(self.announced())

    def announced(self) -> dict[bytes, dict[str, str]]:
        """What the participants that answered so far announced: the properties of each (spdp.
        announced_properties: Cyclone DDS names its host and process there), by GUID prefix."""
        while True:
            try:
                self._take(self._socket.recv(65536))
            except (BlockingIOError, InterruptedError):
                return dict(self._heard)

    def answer_heartbeats(self, seconds: float) -> None:
        """Take what comes for at most ``seconds``, until every participant asked has answered and has
        been asked for its endpoints (a fetching probe): what they send later waits in the socket's
        buffer, taken by ``announced`` and ``pass_on_endpoints``. No thread of its own: one taking each
        message while rclpy loads held Python's lock so often that the participant came 60 ms later."""
        if self._fetcher is None:
            return
        deadline = time.monotonic() + seconds
        try:
            while not self._fetcher.asked_all(self._asked) and (left := deadline - time.monotonic()) > 0:
                self._socket.settimeout(left)
                with contextlib.suppress(TimeoutError, InterruptedError):
                    self._take(self._socket.recv(65536))
        finally:
            self._socket.setblocking(False)

    def _take(self, message: bytes) -> None:
        if not message.startswith(b"RTPS") or len(message) < RTPS_HEADER_BYTES:
            return
        prefix = message[8:RTPS_HEADER_BYTES]
        if SPDP_WRITER in message:  # an announcement: a participant's answer (a fetching probe gets more)
            if prefix not in self._heard:
                self._pass_on(message)
            self._heard[prefix] = announced_properties(message) or self._heard.get(prefix, {})
            locators = (announced_locators(message), announced_locators(message, PID_DEFAULT_UNICAST_LOCATOR))
            if any(locators):
                self._locators[prefix] = locators
        if self._fetcher is not None:
            for request, address in self._fetcher.take(prefix, message, self._locators.get(prefix, ([], []))[0]):
                self._send(request, address)

    def _pass_on(self, answer: bytes) -> None:
        """Send an answer directed to the stand-in, undirected, to this process's participants."""
        message = undirected(answer)
        if message is None:  # no INFO_DST: nothing to pass on (roc.ros.spdp.undirected)
            return
        for address in self._ours:
            self._send(message, address)

    def pass_on_endpoints(self) -> int:
        """Send this process's participants the endpoint announcements fetched so far, each a few times
        (PASS_ON_TIMES: one that comes before a participant has taken in its writer's participant is
        dropped); returns how many messages went. The last ``ask`` found those participants."""
        if self._fetcher is None:
            return 0
        self.announced()  # what came meanwhile
        messages = self._fetcher.to_pass_on() if self._ours else []
        for message in messages:
            for address in self._ours:
                self._send(message, address)
        return len(messages)

    def _send(self, message: bytes, address: tuple[str, int]) -> None:
        try:
            self._socket.sendto(message, (_reachable(address[0]), address[1]))
        except OSError:  # gone meanwhile, or a full buffer: heard, or asked for, again later
            pass

    def prompt(self, reader_prefix: bytes, writer_prefix: bytes, endpoints: list[tuple[bytes, bytes]],
               count: int) -> bool:
        """Send the participant ``writer_prefix`` that answered ACKNACKs of this process's participant
        ``reader_prefix`` for ``endpoints`` (reader and writer entity ids) numbered ``count``
        (roc.ros.spdp.acknack_prompt): those of built-in writers (discovery's) at the metatraffic locators
        it announced, the others at its default ones, where it takes each (roc.ros.vendors.fastdds).
        Not when it was sent the same in the last PROMPT_AGAIN_SECONDS; returns whether they went."""
        now, key = time.monotonic(), (writer_prefix, tuple(endpoints))
        locators = self._locators.get(writer_prefix)
        if locators is None or now - self._prompted_at.get(key, -PROMPT_AGAIN_SECONDS) < PROMPT_AGAIN_SECONDS:
            return False
        self._prompted_at[key] = now
        for addresses, builtin in zip(locators, (True, False)):
            chosen = [pair for pair in endpoints if is_builtin(pair[1]) == builtin]
            if chosen:
                message = acknack_prompt(reader_prefix, writer_prefix, chosen, count)
                for address in addresses:
                    self._send(message, address)
        return True

    def close(self) -> None:
        self._socket.close()


class EndpointFetch:
    """What a fetching probe (LocalParticipantProbe) asked the writers of endpoint announcements for, and
    what they sent: ``take`` answers each of their HEARTBEATs to one of its stand-ins with a request for
    what it lacks, ``to_pass_on`` gives what came, to pass on to this process's participants. Only from
    the writers of a vendor that answers a request late (roc.ros.vendors: Fast DDS, 0.1 s); a writer
    that answers at once is acknowledged all it has."""

    def __init__(self) -> None:
        self.stand_ins: set[bytes] = set()  # the GUID prefixes of the probe's stand-ins
        # (participant's GUID prefix, writer entity id) -> sequence number -> the message that brought it
        self._fetched: dict[tuple[bytes, bytes], dict[int, bytes]] = {}
        # (stand-in, participant, writer) -> ACKNACKs sent; the range of the latest HEARTBEAT not answered yet
        self._requests: dict[tuple[bytes, bytes, bytes], int] = {}
        self._unanswered: dict[tuple[bytes, bytes, bytes], tuple[int, int]] = {}
        self._passed_on: dict[bytes, int] = {}  # message -> times passed on

    def take(self, prefix: bytes, message: bytes, locators: list[tuple[str, int]]) -> list[tuple[bytes, tuple]]:
        """Keep the endpoint announcements of the participant ``prefix`` in ``message``; return the requests
        its HEARTBEATs call for, each with where to send it: its metatraffic ``locators``, which its
        announcement may bring after a HEARTBEAT (that one is answered then)."""
        vendor = vendors.of_prefix(prefix)
        late = vendor is not None and vendor.answers_endpoint_requests_late
        for writer, number in data_sequence_numbers(message) if late else ():
            if writer in ENDPOINT_READERS:
                self._fetched.setdefault((prefix, writer), {})[number] = undirected(message) or message
        for stand_in, writer, first, last in heartbeats(message):
            if writer in ENDPOINT_READERS and stand_in in self.stand_ins:
                self._unanswered[(stand_in, prefix, writer)] = (first, last)
        requests = []
        for key in [key for key in self._unanswered if key[1] == prefix and locators]:
            (first, last), (stand_in, _, writer) = self._unanswered.pop(key), key
            have = self._fetched.get((prefix, writer), {})
            window = range(first, min(last, first + MAX_REQUESTED - 1) + 1)  # what one request can ask for
            missing = [number for number in window if number not in have]
            if late and missing and self._requests.get(key, 0) < MAX_REQUESTS:
                asked = (missing[0], missing[-1])
            else:  # all it has, acknowledged: a writer that answers at once is not fetched from
                asked = (last + 1, last)
            self._requests[key] = count = self._requests.get(key, 0) + 1
            request = acknack_request(stand_in, prefix, ENDPOINT_READERS[writer], writer, *asked, count)
            requests += [(request, address) for address in locators]
        return requests

    def asked_all(self, participants: int) -> bool:
        """Whether the writers of endpoint announcements of ``participants`` participants have been asked."""
        asked = {(prefix, writer) for _, prefix, writer in self._requests}
        return len(asked) >= len(ENDPOINT_READERS) * participants

    def to_pass_on(self) -> list[bytes]:
        """The messages fetched that went on fewer than PASS_ON_TIMES times (counted as passed on now)."""
        messages = [message for fetched in self._fetched.values() for message in fetched.values()
                    if self._passed_on.get(message, 0) < PASS_ON_TIMES]
        for message in messages:
            self._passed_on[message] = self._passed_on.get(message, 0) + 1
        return messages


def early_probe(environment: Mapping[str, str] = os.environ) -> LocalParticipantProbe | None:
    """A probe of this process's ROS domain that fetches endpoint announcements, asked now: made before
    this process's participant, while rclpy loads (LocalParticipantProbe, ``fetches_endpoints``). None on
    a middleware without RTPS, or where the domain id is no number (rcl then says what is wrong)."""
    domain = environment.get("ROS_DOMAIN_ID", "").strip() or "0"
    if not domain.isdigit() or not vendors.speaks_rtps(middleware(environment)):
        return None
    probe = LocalParticipantProbe(int(domain), fetches_endpoints=True)
    probe.ask()
    probe.answer_heartbeats(EARLY_ANSWER_SECONDS)
    return probe


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


def local_peers_discovered(expected: int | None, heard: set[bytes], writers: list[Any]) -> bool | None:
    """Every participant of another process on this host has been discovered: as many answered the probe
    (``heard``, LocalParticipantProbe) as ``expected`` (local_participant_count) and each has a
    ``ros_discovery_info`` writer among ``writers`` (rclpy endpoint infos). None when the participants of
    this host cannot be counted (not Linux)."""
    if expected is None:
        return None
    discovered = {participant_prefix(bytes(info.endpoint_gid)) for info in writers}
    return len(heard) >= expected and heard <= discovered


def own_participant(told: Mapping[bytes, Told], node_name: str) -> bytes | None:
    """The GUID prefix of this process's participant: the one whose ``ros_discovery_info`` message
    (``told``, by participant GUID prefix) lists its node ``node_name`` (its own messages come to it too);
    None before it has come."""
    return next((prefix for prefix, latest in told.items() if any(name == node_name for _, name in latest.nodes)),
                None)


def writers_to_prompt(own: bytes, heard: set[bytes], told: Mapping[bytes, Told], writers: list[Any],
                      readers: list[Any]) -> dict[bytes, list[tuple[bytes, bytes]]]:
    """By GUID prefix, each participant of this host that answered the probe (``heard``) and whose
    ``ros_discovery_info`` message has not come (``told``): which of its writers to prompt to send this
    process's participant ``own`` a HEARTBEAT, as (reader, writer) entity ids: its endpoint discovery
    writers for own's, and, once it is discovered (``writers``: rclpy endpoint infos of the topic's
    writers), its ``ros_discovery_info`` writer for own's readers of the topic (``readers``)."""
    ours = [bytes(info.endpoint_gid)[ENTITY_ID] for info in readers
            if participant_prefix(bytes(info.endpoint_gid)) == own]
    theirs = {participant_prefix(bytes(info.endpoint_gid)): bytes(info.endpoint_gid)[ENTITY_ID] for info in writers}
    return {prefix: [SEDP_PUBLICATIONS, SEDP_SUBSCRIPTIONS, *((reader, theirs[prefix]) for reader in ours
                                                               if prefix in theirs)]
            for prefix in sorted(heard - told.keys() - {own})}


@dataclass(frozen=True)
class Told:
    """What a participant's latest ``ros_discovery_info`` message lists (roc.ros.discovery_info): its
    nodes as (namespace, name) and the GIDs of their endpoints."""

    nodes: frozenset[tuple[str, str]]
    endpoints: frozenset[bytes]


def incomplete_participants(writers: list[Any], told: Mapping[bytes, Told], endpoints: set[bytes],
                            nodes: set[tuple[str, str]]) -> int:
    """How many participants whose ``ros_discovery_info`` writer is among ``writers`` (rclpy endpoint
    infos) are not wholly discovered yet: their message (``told``, by participant GUID prefix) has not
    come, or it lists a node not among ``nodes`` (namespace, name) or an endpoint whose GID is not among
    ``endpoints``. This process's own participants count as any other: their messages come to it too.
    A participant whose nodes are all roc's own (its daemon's, another roc command's: roc.ros.protocol.
    is_own_node) is complete once its message has come: roc leaves those nodes out of every answer, and
    on Cyclone DDS such a message may list a reader that is gone (rmw_cyclonedds 2.2.2 leaves a destroyed
    subscription listed, ros2/rmw_cyclonedds#594: the reader of roc's daemon's first wait), which made
    every query beside roc's daemon wait out its period."""
    incomplete = 0
    for info in writers:
        latest = told.get(participant_prefix(bytes(info.endpoint_gid)))
        if latest is not None and all(is_own_node(name) for _, name in latest.nodes):
            continue
        if latest is None or not latest.nodes <= nodes or not latest.endpoints <= endpoints:
            incomplete += 1
    return incomplete
