"""The facts about a DDS vendor that roc acts on (one instance per vendor module)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Vendor:
    name: str
    vendor_id: bytes  # the first two bytes of its participants' GUID prefixes (RTPS 9.3.1.5)
    middlewares: tuple[str, ...]  # the RMW implementations on it
    # how much longer a fresh participant of this vendor may need for a participant it heard only at that
    # participant's next periodic announcement (roc.ros.graph: Graph.wait_for_discovery)
    late_answer_seconds: float
    # the vendor ids of servers a request of this vendor's clients is known to crash
    crashes_servers_of: tuple[bytes, ...] = ()
    crash_report: str = ""  # where that is told
