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
    # a participant of this vendor drops a writer's HEARTBEATs that come before it has taken in the writer's
    # participant's announcement, and its own first ACKNACK does not make every vendor's writer send
    # another: roc prompts the writers of the participants it has not wholly heard yet (roc.ros.graph)
    loses_early_heartbeats: bool = False
    # its writers of endpoint announcements answer a reader's request late (Fast DDS: 0.1 s), so roc fetches
    # their announcements before its participant exists (roc.ros.discovery.early_probe)
    answers_endpoint_requests_late: bool = False
    # the count of an ACKNACK (roc.ros.spdp.acknack_prompt) that makes a writer of this vendor send a
    # HEARTBEAT at once and still take every later ACKNACK of that reader; None: roc prompts none
    prompt_count: int | None = None
