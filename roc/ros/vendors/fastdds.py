"""eProsima Fast DDS (rmw_fastrtps_cpp, rmw_fastrtps_dynamic_cpp, the ROS 2 wheels' own).

Its GUID prefix carries its process (rtps/common/GuidUtils.hpp, 2.14 and 3.x): bytes 0-1 the vendor id
(01.0f), 2-3 a host id, 4-5 the 16 low bits of the process id (little endian), 6-7 random, 8-11 a counter
of the process's participants (``process_bits``).

A fresh Fast DDS participant sends its first announcement before it listens, so it hears the answers of
the participants already there only at their next periodic announcement, by default every 3 s
(``late_answer_seconds``): roc asks them to announce themselves again at once
(roc.ros.discovery.ask_local_participants_to_announce; why: roc.ros.spdp). roc's own participants take
roc's Fast DDS profiles (roc.ros.graph.PROFILES)."""

from __future__ import annotations

from roc.ros.vendors.vendor import Vendor

VENDOR = Vendor("Fast DDS", vendor_id=b"\x01\x0f", middlewares=("rmw_fastrtps_cpp", "rmw_fastrtps_dynamic_cpp"),
                late_answer_seconds=3.0)  # its default period of a participant's announcements


def process_bits(prefix: bytes) -> int | None:
    """The 16 low bits of the process id in a Fast DDS GUID prefix (None for another vendor's)."""
    if prefix[:2] != VENDOR.vendor_id or len(prefix) < 6:
        return None
    return int.from_bytes(prefix[4:6], "little")
