"""What a fetching probe (roc.ros.discovery.LocalParticipantProbe) asks the writers of endpoint
announcements for, and what they send it: the announcements of their endpoints, kept to pass on to this
process's participants once they exist. Only from the writers of a vendor that answers a request late
(roc.ros.vendors: Fast DDS, 0.1 s); a writer that answers at once is acknowledged all it has. No rclpy."""

from __future__ import annotations

from roc.ros import vendors
from roc.ros.spdp import (
    MAX_REQUESTED,
    SEDP_PUBLICATIONS,
    SEDP_SUBSCRIPTIONS,
    acknack_request,
    data_sequence_numbers,
    heartbeats,
    undirected,
)

PASS_ON_TIMES = 3  # to_pass_on: each message at most this often (one that comes too early is dropped)
MAX_REQUESTS = 3  # requests to one writer at most, then every HEARTBEAT is acknowledged
# the writers of endpoint announcements (RTPS 9.3.1.3), each with its reader: a fetching stand-in's
ENDPOINT_READERS = {SEDP_PUBLICATIONS[1]: SEDP_PUBLICATIONS[0], SEDP_SUBSCRIPTIONS[1]: SEDP_SUBSCRIPTIONS[0]}


class EndpointFetch:
    """What a fetching probe (LocalParticipantProbe) asked the writers of endpoint announcements for, and
    what they sent: ``take`` answers each of their HEARTBEATs to one of its stand-ins with a request for
    what it lacks, ``to_pass_on`` gives what came."""

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
