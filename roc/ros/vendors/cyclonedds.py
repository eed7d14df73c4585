"""Eclipse Cyclone DDS (rmw_cyclonedds_cpp).

Its GUID prefix (vendor id 01.10) carries no host and no process: a participant names its host, process
and process id only in its announcement, as the properties ``__Hostname``, ``__ProcessName`` and
``__Pid``, which rmw does not pass on (DDS built-in topics only). On the LOCALHOST and SUBNET discovery
ranges rmw_cyclonedds gives each participant the RTPS ports of a participant index, as Fast DDS does, so
roc counts this host's participants by port for both (roc.ros.discovery). The message info of what it
delivers names the writer with an instance handle (8 bytes and zeros), not the writer's GUID, and it
gives no publication sequence numbers (roc.ros.raw_subscription: loss unknown).

roc's discovery wait adds no announcement period for a Cyclone participant (``late_answer_seconds``): roc
asks every participant of this host to announce itself to it at once (roc.ros.discovery), which Cyclone's
participants, as Fast DDS's, do within milliseconds, and Fast DDS's 3 s period is not Cyclone's.

A fresh Cyclone participant drops the first HEARTBEATs of a participant that answers its announcement
(``loses_early_heartbeats``): the answer and those HEARTBEATs come in one burst, and Cyclone takes in an
announcement on another thread than the one that reads the HEARTBEATs after it (0.10's q_receive.c:
handle_SPDP queues it for dq.builtin; handle_Heartbeat drops a HEARTBEAT of a writer it does not know).
Its own first ACKNACK to each writer then (q_xevent.c: make_preemptive_acknack, sequence number set from
1, count 0) makes a Fast DDS writer send nothing, so it heard a Fast DDS participant's endpoints only at
that writer's next periodic HEARTBEAT (Fast DDS's endpoint discovery: every second) and its
``ros_discovery_info`` at that writer's (every 3 s): a first query beside Fast DDS processes took 2.2 to
3.4 s. roc prompts those writers instead (roc.ros.graph, roc.ros.vendors.fastdds). Fast DDS's writers of
endpoint announcements then answer the participant's request 0.1 s after it comes (EDPSimple's
``edp_nack_response_delay``), where Cyclone's own answer at once: a query fetches those announcements
before its participant exists, while rclpy loads, and passes them on to it
(roc.ros.discovery.early_probe).

A service request from a Cyclone client can crash a Fast DDS server of Jazzy (rmw_fastrtps 8.4.3 reads the
request's header as a sequence length and allocates gigabytes: ros2/rmw_cyclonedds#577), so roc on Cyclone
calls no service of a Fast DDS node (``crashes_servers_of``).

A Cyclone participant that closes waits until readers have acknowledged its reliable writers' last
messages, up to its ``WriterLingerDuration`` (1 s): 0.15 s of every query process's 0.5 s here, 0.19 s
beside Fast DDS processes. A participant that only asks (queries, and requests whose answers it waits
for) sends nothing anyone still needs when it closes, so roc's are told not to wait (``close_at_once``);
one that publishes and exits (``roc topic pub --once``, ``roc bag play``) must wait."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator, MutableMapping

from roc.ros.protocol import middleware
from roc.ros.vendors.vendor import Vendor

VENDOR = Vendor("Cyclone DDS", vendor_id=b"\x01\x10", middlewares=("rmw_cyclonedds_cpp",), late_answer_seconds=0.0,
                loses_early_heartbeats=True, crashes_servers_of=(b"\x01\x0f",), crash_report="ros2/rmw_cyclonedds#577")

URI_VARIABLE = "CYCLONEDDS_URI"  # Cyclone's configuration: sources separated by commas, the later ones winning
NO_LINGER = "<Internal><WriterLingerDuration>0s</WriterLingerDuration></Internal>"


@contextlib.contextmanager
def close_at_once(environment: MutableMapping[str, str] = os.environ) -> Iterator[None]:
    """While the participants made in it are made: have them close without waiting for their last
    messages to be acknowledged, unless the middleware is not Cyclone DDS or the user's configuration sets
    that wait. Cyclone reads its configuration as a process's first participant of a domain is made."""
    configured = environment.get(URI_VARIABLE)
    if middleware(environment) not in VENDOR.middlewares or "WriterLingerDuration" in (configured or ""):
        yield
        return
    environment[URI_VARIABLE] = f"{configured},{NO_LINGER}" if (configured or "").strip() else NO_LINGER
    try:
        yield
    finally:
        if configured is None:
            environment.pop(URI_VARIABLE, None)
        else:
            environment[URI_VARIABLE] = configured
