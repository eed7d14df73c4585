"""What differs between DDS vendors, one module per vendor (``fastdds``, ``cyclonedds``), as
roc/distribution.py holds what differs between distributions: every other module asks ``of_prefix`` (the
vendor of a participant, from the vendor id its RTPS GUID prefix starts with) or ``of_middleware`` (the
vendor of an RMW implementation) instead of assuming one vendor's ways. What works for any RTPS vendor
(the port formula, a stand-in's announcement, GUID prefixes shared by a participant and its endpoints)
stays in roc.ros.discovery. No rclpy."""

from __future__ import annotations

from roc.ros.vendors import cyclonedds, fastdds
from roc.ros.vendors.vendor import Vendor

VENDORS = (fastdds.VENDOR, cyclonedds.VENDOR)
# Middlewares whose discovery is not DDS's (no RTPS ports, no SPDP announcements, no ros_discovery_info):
# roc sends them no stand-in announcement and counts no participants by port.
NOT_RTPS = {"rmw_zenoh_cpp": "Zenoh (a router, or peers scouting by multicast)"}


def request_crash(client_middleware: str, server_prefix: bytes) -> str | None:
    """Why a service request from a client of ``client_middleware`` must not go to a server whose
    participant GUID prefix (or endpoint GID) is ``server_prefix`` (it is known to crash it), else None."""
    client, server = of_middleware(client_middleware), of_prefix(server_prefix)
    if client is None or server is None or server.vendor_id not in client.crashes_servers_of:
        return None
    return f"a {client.name} request can crash a {server.name} node ({client.crash_report})"


def discovery_of(middleware: str) -> str:
    """How the participants of ``middleware`` find each other, in a few words (roc doctor says it)."""
    return NOT_RTPS.get(middleware, "DDS (RTPS participant announcements)")


def speaks_rtps(middleware: str) -> bool:
    """Whether ``middleware``'s participants discover each other with RTPS (every DDS; not rmw_zenoh)."""
    return middleware not in NOT_RTPS


def of_prefix(prefix: bytes) -> Vendor | None:
    """The vendor of the participant whose GUID prefix (or GID) is ``prefix``; None for another vendor's."""
    return next((vendor for vendor in VENDORS if prefix[:2] == vendor.vendor_id), None)


def of_middleware(name: str) -> Vendor | None:
    """The vendor of the RMW implementation ``name`` (rmw_fastrtps_cpp, ...); None for a middleware that
    is no DDS roc knows (rmw_zenoh_cpp, ...)."""
    return next((vendor for vendor in VENDORS if name in vendor.middlewares), None)
