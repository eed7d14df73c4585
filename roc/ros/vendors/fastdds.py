"""eProsima Fast DDS (rmw_fastrtps_cpp, rmw_fastrtps_dynamic_cpp, the ROS 2 wheels' own).

Its GUID prefix carries its process (rtps/common/GuidUtils.hpp, 2.14 and 3.x): bytes 0-1 the vendor id
(01.0f), 2-3 a host id, 4-5 the 16 low bits of the process id (little endian), 6-7 random, 8-11 a counter
of the process's participants (``process_bits``).

A fresh Fast DDS participant sends its first announcement before it listens, so it hears the answers of
the participants already there only at their next periodic announcement, by default every 3 s
(``late_answer_seconds``): roc asks them to announce themselves again at once
(roc.ros.discovery.ask_local_participants_to_announce; why: roc.ros.spdp). roc's own participants take
roc's Fast DDS profiles (``PROFILES``; ``use_profile``), unless the user chose a
profile file.

A Fast DDS writer sends a HEARTBEAT at once to a reader whose ACKNACK has an empty set of sequence numbers
from 0, as a Fast DDS reader's first ACKNACK has (StatefulWriter::process_acknack, 2.14 and 3.x), if its
count is not below the next one expected from that reader (ReaderProxy::check_and_set_acknack_count);
the next one expected is then the count plus one, in 32 bits. roc prompts a Fast DDS writer for a Cyclone
DDS reader that lost its first HEARTBEATs (roc.ros.vendors.cyclonedds) with the count 0xFFFFFFFF
(``prompt_count``): always taken, and the next one expected wraps to 0, so every ACKNACK the reader sends
later is taken too (the reader's own count goes on from 1). The writer takes an ACKNACK on the port it
listens on for that endpoint: the discovery (metatraffic) port for discovery's endpoints, the default one
for the others (roc.ros.discovery.LocalParticipantProbe.prompt).

Its writers of endpoint announcements answer a reader's request 0.1 s after it comes (EDPSimple's
``edp_nack_response_delay``, a constant of 2.14 and 3.x; measured: 100 to 102 ms from the request to
the data, for each of three processes), and a fresh participant asks only once it has heard them: a
first query waited for it (``answers_endpoint_requests_late``). roc asks them before its participant
exists (roc.ros.discovery.early_probe)."""

from __future__ import annotations

import os
from collections.abc import Mapping, MutableMapping
from pathlib import Path

from roc import distribution
from roc.ros.protocol import middleware
from roc.ros.vendors.vendor import Vendor

VENDOR = Vendor("Fast DDS", vendor_id=b"\x01\x0f", middlewares=("rmw_fastrtps_cpp", "rmw_fastrtps_dynamic_cpp"),
                late_answer_seconds=3.0,  # its default period of a participant's announcements
                answers_endpoint_requests_late=True, prompt_count=0xFFFFFFFF)


def process_bits(prefix: bytes) -> int | None:
    """The 16 low bits of the process id in a Fast DDS GUID prefix (None for another vendor's)."""
    if prefix[:2] != VENDOR.vendor_id or len(prefix) < 6:
        return None
    return int.from_bytes(prefix[4:6], "little")


PROFILE_VARIABLES = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")  # Fast DDS 2's; 3's
# roc's Fast DDS profiles by Fast DDS major version: 3 (Kilted on) renamed elements of 2's (Jazzy) and
# rejects a whole file that has one of 2's names (fastdds3_participant.xml), and 2 does the same
_HERE = Path(__file__).parent
PROFILES = {2: (_HERE / "fastdds_participant.xml", _HERE / "fastdds_bridge.xml"),
            3: (_HERE / "fastdds3_participant.xml", _HERE / "fastdds3_bridge.xml")}
# this environment's (roc.distribution): every roc participant's, and a bridge's
PARTICIPANT_PROFILE, BRIDGE_PROFILE = PROFILES[distribution.current().fastdds_major]
OWN_PROFILES = {str(path) for pair in PROFILES.values() for path in pair}


def users_profile(environment: Mapping[str, str] = os.environ) -> str | None:
    """The Fast DDS profile file the user chose, if any (roc's own do not count)."""
    return next((environment[v] for v in PROFILE_VARIABLES
                 if environment.get(v) and environment[v] not in OWN_PROFILES), None)


def use_profile(profile: Path, environment: MutableMapping[str, str] = os.environ) -> None:
    """Have Fast DDS load ``profile`` for this process's participants (it reads the file once, at the
    first), unless the user chose one or the middleware is not Fast DDS. Only through the variable this
    distribution's Fast DDS reads first: Kilted's rmw warns on stderr that the other one is deprecated."""
    if middleware(environment).startswith("rmw_fastrtps") and users_profile(environment) is None:
        for variable in PROFILE_VARIABLES:  # roc's own, inherited from the roc process that started this one
            environment.pop(variable, None)
        environment[distribution.current().profiles_variable] = str(profile)
