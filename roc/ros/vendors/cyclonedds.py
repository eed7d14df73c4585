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

A service request from a Cyclone client can crash a Fast DDS server of Jazzy (rmw_fastrtps 8.4.3 reads the
request's header as a sequence length and allocates gigabytes: ros2/rmw_cyclonedds#577), so roc on Cyclone
calls no service of a Fast DDS node (``crashes_servers_of``)."""

from __future__ import annotations

from roc.ros.vendors.vendor import Vendor

VENDOR = Vendor("Cyclone DDS", vendor_id=b"\x01\x10", middlewares=("rmw_cyclonedds_cpp",), late_answer_seconds=0.0,
                crashes_servers_of=(b"\x01\x0f",), crash_report="ros2/rmw_cyclonedds#577")
