"""The RTPS messages roc writes itself: a participant announcement (SPDP DATA(p), RTPS 2.3 8.5.3 and
9.6.2) of a short-lived stand-in participant that names roc's own participant's discovery port; what roc
reads of the announcements that answer it, their properties (``announced_properties``) and locators
(``announced_locators``); such an answer made fit for roc's own participant (``undirected``); and the
ACKNACKs that prompt a writer to send roc's participant a HEARTBEAT (``acknack_prompt``).

Why the stand-in: a Fast DDS participant (2.14 and 3.x alike) sends its first announcement before it listens
(RTPSParticipantImpl::enable), so the announcements other participants send back at once to the newcomer
are lost, and it hears them only at their next periodic announcement, up to 3 s later. Every participant
answers a participant it has not seen before by announcing itself to that participant's metatraffic
locators (Fast DDS's PDPStatelessWriter marks it an interested reader); the stand-in's locators are the
fresh participant's own port, so the answers reach a participant that now listens. The stand-in has only
the announcement endpoints (no endpoint discovery, no ROS enclave: rmw ignores it) and a lease of one
second, after which every participant forgets it.

Why the prompts: a fresh Cyclone DDS participant drops the first HEARTBEATs of the participants that
answer it, and Fast DDS's writers send the next only a period later (roc.ros.vendors.cyclonedds); an
ACKNACK of the reader makes them send one at once (roc.ros.vendors.fastdds).
"""

from __future__ import annotations

import ipaddress
import os
import struct
from collections.abc import Iterator, Sequence

VENDOR_UNKNOWN = b"\x00\x00"  # roc is no DDS vendor (RTPS 9.3.1.5)
PROTOCOL_VERSION = b"\x02\x03"
SUBMESSAGE_DATA = 0x15
FLAGS_LITTLE_ENDIAN_WITH_DATA = 0x05  # E and D flags
SPDP_READER = bytes.fromhex("000100c7")
SPDP_WRITER = bytes.fromhex("000100c2")
PARTICIPANT_ENTITY = bytes.fromhex("000001c1")
PL_CDR_LE = b"\x00\x03\x00\x00"
LOCATOR_KIND_UDPV4 = 1
# parameter ids (RTPS 9.6.2.2.2, table 9.12)
PID_SENTINEL = 0x0001
PID_PARTICIPANT_LEASE_DURATION = 0x0002
PID_DOMAIN_ID = 0x000F
PID_PROTOCOL_VERSION = 0x0015
PID_VENDORID = 0x0016
PID_DEFAULT_UNICAST_LOCATOR = 0x0031
PID_METATRAFFIC_UNICAST_LOCATOR = 0x0032
PID_PARTICIPANT_GUID = 0x0050
PID_BUILTIN_ENDPOINT_SET = 0x0058
PID_PROPERTY_LIST = 0x0059
FLAG_LITTLE_ENDIAN, FLAG_INLINE_QOS = 0x01, 0x02
PARTICIPANT_ANNOUNCER_AND_DETECTOR = 0x3  # the builtin endpoints every stand-in has
ENDPOINT_DETECTORS = 0x8 | 0x20  # a fetching stand-in's readers of endpoint announcements (publications, subscriptions)
MAX_REQUESTED = 256  # sequence numbers one ACKNACK can ask for (RTPS 9.4.2.6: a SequenceNumberSet's bitmap)
SUBMESSAGE_ACKNACK = 0x06
SUBMESSAGE_HEARTBEAT = 0x07
SUBMESSAGE_DATA_FRAG = 0x16
SUBMESSAGE_INFO_DST = 0x0E  # what follows in the message is for the participant it names only (RTPS 8.3.7.7)
RTPS_HEADER_BYTES = 20  # "RTPS", version, vendor id, then the sender's GUID prefix (RTPS 8.3.3.1)
GUID_PREFIX_BYTES = 12
ZERO_LENGTH_SUBMESSAGES = (0x01, 0x09)  # PAD and INFO_TS: a length of 0 is theirs; any other's runs to the end
LEASE_SECONDS = 1
# the endpoint discovery (SEDP) endpoints every participant has (RTPS 9.3.1.3): (reader, writer) entity ids
SEDP_PUBLICATIONS = (bytes.fromhex("000003c7"), bytes.fromhex("000003c2"))
SEDP_SUBSCRIPTIONS = (bytes.fromhex("000004c7"), bytes.fromhex("000004c2"))


def _parameter(pid: int, value: bytes) -> bytes:
    value += b"\0" * (-len(value) % 4)
    return struct.pack("<HH", pid, len(value)) + value


def _udp_locator(address: str, port: int) -> bytes:
    return struct.pack("<iI", LOCATOR_KIND_UDPV4, port) + bytes(12) + ipaddress.IPv4Address(address).packed


def stand_in_announcement(domain_id: int, locators: list[tuple[str, int]], prefix: bytes | None = None,
                          fetches_endpoints: bool = False) -> bytes:
    """One RTPS message: the announcement of a stand-in participant in ``domain_id`` whose metatraffic and
    default unicast locators are ``locators`` (IPv4 address, UDP port), with GUID prefix ``prefix``
    (by default a random one: new to every participant each time); ``fetches_endpoints``: it also has
    the readers of endpoint announcements, so every participant offers it its endpoints."""
    prefix = prefix or os.urandom(12)
    builtin = PARTICIPANT_ANNOUNCER_AND_DETECTOR | (ENDPOINT_DETECTORS if fetches_endpoints else 0)
    parameters = [
        _parameter(PID_PROTOCOL_VERSION, PROTOCOL_VERSION),
        _parameter(PID_VENDORID, VENDOR_UNKNOWN),
        _parameter(PID_DOMAIN_ID, struct.pack("<I", domain_id)),
        _parameter(PID_PARTICIPANT_GUID, prefix + PARTICIPANT_ENTITY),
        *(_parameter(pid, _udp_locator(address, port)) for address, port in locators
          for pid in (PID_METATRAFFIC_UNICAST_LOCATOR, PID_DEFAULT_UNICAST_LOCATOR)),
        _parameter(PID_PARTICIPANT_LEASE_DURATION, struct.pack("<iI", LEASE_SECONDS, 0)),
        _parameter(PID_BUILTIN_ENDPOINT_SET, struct.pack("<I", builtin)),
        struct.pack("<HH", PID_SENTINEL, 0),
    ]
    sequence_number = struct.pack("<iI", 0, 1)
    # extraFlags, octetsToInlineQos (from after this field to the writer sequence number's end: 16)
    body = struct.pack("<HH", 0, 16) + SPDP_READER + SPDP_WRITER + sequence_number + PL_CDR_LE + b"".join(parameters)
    submessage = bytes([SUBMESSAGE_DATA, FLAGS_LITTLE_ENDIAN_WITH_DATA]) + struct.pack("<H", len(body)) + body
    return b"RTPS" + PROTOCOL_VERSION + VENDOR_UNKNOWN + prefix + submessage


def announced_properties(message: bytes) -> dict[str, str]:
    """The properties (PID_PROPERTY_LIST) of the participant announcement in an RTPS message, {} when it
    holds none. Cyclone DDS names its participant's host and process there (``__Hostname``, ``__Pid``,
    ``__ProcessName``), which no rmw call tells."""
    try:
        for pid, at, order in _announced_parameters(message):
            if pid == PID_PROPERTY_LIST:
                (count,) = struct.unpack_from(order + "I", message, at)
                at, found = at + 4, {}
                for _ in range(count):
                    name, at = _string(message, at, order)
                    value, at = _string(message, at, order)
                    found[name] = value
                return found
    except (struct.error, IndexError, UnicodeDecodeError):
        pass
    return {}


def announced_locators(message: bytes, pid_wanted: int = PID_METATRAFFIC_UNICAST_LOCATOR) -> list[tuple[str, int]]:
    """The UDPv4 unicast locators (address, port) of the participant announcement in an RTPS message, []
    when it holds none: its metatraffic ones (where the participant takes the traffic of its built-in
    endpoints: discovery), or with ``pid_wanted=PID_DEFAULT_UNICAST_LOCATOR`` its default ones (its
    endpoints' traffic, unless an endpoint announces locators of its own)."""
    locators = []
    try:
        for pid, at, order in _announced_parameters(message):
            if pid == pid_wanted:
                kind, port = struct.unpack_from(order + "iI", message, at)
                if kind == LOCATOR_KIND_UDPV4:
                    locators.append((str(ipaddress.IPv4Address(message[at + 20:at + 24])), port))
    except (struct.error, IndexError, ValueError):
        return []
    return locators


def _announced_parameters(message: bytes) -> Iterator[tuple[int, int, str]]:
    """Each parameter of the participant announcement (the SPDP writer's DATA) in an RTPS message: its id,
    where its value starts and the byte order of the list ("<" or ">"); none when the message holds no
    announcement. Raises struct.error or IndexError on a message cut short."""
    if not message.startswith(b"RTPS"):
        return
    for kind, order, start, _ in _submessages(message):
        body = start + 4
        if kind == SUBMESSAGE_DATA and message[body + 8:body + 12] == SPDP_WRITER:
            (to_inline_qos,) = struct.unpack_from(order + "H", message, body + 2)
            payload = body + 4 + to_inline_qos
            if message[start + 1] & FLAG_INLINE_QOS:
                payload = _parameters_end(message, payload, order)
            yield from _parameters(message, payload)
            return


def _parameters_end(message: bytes, offset: int, order: str) -> int:
    """Where the parameter list starting at ``offset`` ends (after its sentinel)."""
    while True:
        pid, length = struct.unpack_from(order + "HH", message, offset)
        offset += 4 + length
        if pid == PID_SENTINEL:
            return offset


def _parameters(message: bytes, payload: int) -> Iterator[tuple[int, int, str]]:
    """Each parameter (id, where its value starts, byte order) of the serialized parameter list (PL_CDR_LE
    or _BE) at ``payload``, up to its sentinel."""
    order = "<" if message[payload + 1] == 0x03 else ">"
    offset = payload + 4
    while offset + 4 <= len(message):
        pid, length = struct.unpack_from(order + "HH", message, offset)
        if pid == PID_SENTINEL:
            return
        yield pid, offset + 4, order
        offset += 4 + length


def _string(message: bytes, offset: int, order: str) -> tuple[str, int]:
    """A CDR string (its length with the NUL, the bytes, padding to 4) at ``offset``; and where it ends."""
    (length,) = struct.unpack_from(order + "I", message, offset)
    text = message[offset + 4:offset + 4 + length].rstrip(b"\0").decode()
    return text, offset + 4 + length + (-length % 4)


def undirected(message: bytes) -> bytes | None:
    """The RTPS message ``message`` without its INFO_DST submessages, None when it has none (or is no RTPS
    message). Why: Cyclone DDS answers a participant new to it with an announcement directed to that
    participant (INFO_DST naming its GUID prefix), which any other participant ignores, and it answers
    only participants new to it. So the answer to a fresh Fast DDS participant's first announcement, lost
    while that participant did not listen yet (above), is not made good by the answer to the stand-in,
    which names the stand-in: the participant would hear Cyclone only at Cyclone's next directed
    announcement, 1 s later. That answer undirected is one it takes (roc.ros.discovery.LocalParticipantProbe
    passes it on)."""
    if not message.startswith(b"RTPS"):
        return None
    kept, directed = [message[:RTPS_HEADER_BYTES]], False
    try:
        for kind, _, start, end in _submessages(message):
            if kind == SUBMESSAGE_INFO_DST:
                directed = True
            else:
                kept.append(message[start:end])
    except struct.error:
        return None
    return b"".join(kept) if directed else None


def _submessages(message: bytes) -> Iterator[tuple[int, str, int, int]]:
    """Each submessage of an RTPS message: its kind, byte order ("<" or ">") and where it starts (at its
    header) and ends. Raises struct.error on a message cut short."""
    offset = RTPS_HEADER_BYTES
    while offset + 4 <= len(message):
        kind, flags = message[offset], message[offset + 1]
        order = "<" if flags & FLAG_LITTLE_ENDIAN else ">"
        (length,) = struct.unpack_from(order + "H", message, offset + 2)
        end = len(message) if length == 0 and kind not in ZERO_LENGTH_SUBMESSAGES else offset + 4 + length
        if end > len(message):
            raise struct.error(f"a submessage runs {end - len(message)} bytes past the message's end")
        yield kind, order, offset, end
        offset = end


def heartbeats(message: bytes) -> list[tuple[bytes, bytes, int, int]]:
    """The HEARTBEATs of an RTPS message: the GUID prefix of the participant each is for (INFO_DST's; empty
    for any), its writer's entity id, and the first and last sequence numbers the writer has; [] for a
    message cut short."""
    found, destination = [], b""
    try:
        for kind, order, start, _ in _submessages(message):
            if kind == SUBMESSAGE_INFO_DST:
                destination = message[start + 4:start + 4 + GUID_PREFIX_BYTES]
            elif kind == SUBMESSAGE_HEARTBEAT:
                first_high, first_low, last_high, last_low = struct.unpack_from(order + "iIiI", message, start + 12)
                found.append((destination, message[start + 8:start + 12], first_high << 32 | first_low,
                              last_high << 32 | last_low))
    except struct.error:
        return []
    return found


def data_sequence_numbers(message: bytes) -> list[tuple[bytes, int]]:
    """The writer entity id and sequence number of each DATA (or DATA_FRAG) of an RTPS message; [] for a
    message cut short."""
    found = []
    try:
        for kind, order, start, _ in _submessages(message):
            if kind in (SUBMESSAGE_DATA, SUBMESSAGE_DATA_FRAG):
                high, low = struct.unpack_from(order + "iI", message, start + 16)
                found.append((message[start + 12:start + 16], high << 32 | low))
    except struct.error:
        return []
    return found


def acknack_prompt(reader_prefix: bytes, writer_prefix: bytes, endpoints: Sequence[tuple[bytes, bytes]],
                   count: int) -> bytes:
    """One RTPS message from the participant whose GUID prefix is ``reader_prefix`` to the one whose
    prefix is ``writer_prefix`` (INFO_DST): for each (reader entity id, writer entity id) of ``endpoints``,
    the ACKNACK of a reader that has nothing yet: its set of missing sequence numbers empty from 0, not
    final (as a Fast DDS reader's first, WriterProxy::perform_initial_ack_nack), numbered ``count``."""
    return _to(reader_prefix, writer_prefix, b"".join(_acknack(reader, writer, 0, 0, count)
                                                       for reader, writer in endpoints))


def acknack_request(reader_prefix: bytes, writer_prefix: bytes, reader: bytes, writer: bytes, first: int, last: int,
                    count: int) -> bytes:
    """The ACKNACK, numbered ``count``, of the reader ``reader_prefix``/``reader`` that asks the writer
    ``writer_prefix``/``writer`` for its sequence numbers ``first`` to ``last`` (at most MAX_REQUESTED
    of them), having every one before ``first``; with ``last`` below ``first``, one that has every
    sequence number before ``first`` and asks for none."""
    bits = max(0, min(last - first + 1, MAX_REQUESTED))
    return _to(reader_prefix, writer_prefix, _acknack(reader, writer, first, bits, count))


def _to(sender_prefix: bytes, receiver_prefix: bytes, submessages: bytes) -> bytes:
    """An RTPS message of ``submessages`` from the participant ``sender_prefix`` for ``receiver_prefix``."""
    info_dst = bytes([SUBMESSAGE_INFO_DST, FLAG_LITTLE_ENDIAN]) + struct.pack("<H", len(receiver_prefix))
    return b"RTPS" + PROTOCOL_VERSION + VENDOR_UNKNOWN + sender_prefix + info_dst + receiver_prefix + submessages


def _acknack(reader: bytes, writer: bytes, base: int, bits: int, count: int) -> bytes:
    """An ACKNACK submessage: sequence numbers ``base`` to ``base + bits - 1`` missing, every one below
    ``base`` received (the set's bitmap: most significant bit first, in 32-bit words)."""
    words = [0] * ((bits + 31) // 32)
    for bit in range(bits):
        words[bit // 32] |= 1 << (31 - bit % 32)
    body = reader + writer + struct.pack(f"<iII{len(words)}II", base >> 32, base & 0xFFFFFFFF, bits, *words, count)
    return bytes([SUBMESSAGE_ACKNACK, FLAG_LITTLE_ENDIAN]) + struct.pack("<H", len(body)) + body


def is_builtin(entity_id: bytes) -> bool:
    """Whether ``entity_id`` is a built-in endpoint's (RTPS 9.3.1.2: its kind's two high bits set)."""
    return entity_id[3] & 0xC0 == 0xC0
