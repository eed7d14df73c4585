"""roc tui's nodes list on Cyclone DDS: a node's process, CPU and memory, from what its participant
announces (``__Pid`` and ``__Hostname``: Cyclone DDS writes no process into its GUIDs), read from the
answers to roc's stand-in announcement (roc.ros.spdp, roc.ros.discovery.LocalParticipantProbe)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from helpers.build import DATA
from helpers.graph import graph_env, start_nodes, stop_all, wait_for
from helpers.rmw import CYCLONEDDS, on_middleware, require_cyclonedds

from roc.ros.discovery import LocalParticipantProbe
from roc.ros.spdp import announced_properties, stand_in_announcement
from roc.tui.processes import Processes

SLOT = 49


def test_the_properties_of_a_cyclone_dds_announcement_are_read() -> None:
    """The answer of a participant of rmw_cyclonedds 2.2.2 (Cyclone DDS 0.10.2) to roc's stand-in,
    captured as it came."""
    answer = (DATA / "cyclonedds_spdp_answer.bin").read_bytes()
    assert announced_properties(answer) == {"__ProcessName": "python", "__Pid": "13309", "__Hostname": "vm"}
    assert announced_properties(stand_in_announcement(5, [("127.0.0.1", 7412)])) == {}  # it announces none
    assert announced_properties(b"RTPS" + bytes(30)) == {} and announced_properties(answer[:60]) == {}


@pytest.mark.slow
def test_a_cyclone_dds_node_s_process_is_found_from_its_announcement(tmp_path: Path) -> None:
    require_cyclonedds()
    env = graph_env(SLOT, tmp_path)
    talker = start_nodes([[{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}]],
                         on_middleware(env, CYCLONEDDS))
    domain = int(env["ROS_DOMAIN_ID"])
    try:
        probe = LocalParticipantProbe(domain)
        try:
            probe.ask()
            wait_for(lambda: probe.heard(), timeout=10)
            prefix = next(iter(probe.heard()))
        finally:
            probe.close()
        gid = ".".join(f"{byte:02x}" for byte in prefix + bytes.fromhex("000003c3"))
        snapshot = {"topics": [{"endpoints": {"publishers": [{"node_namespace": "/", "node_name": "talker",
                                                                "gid": gid}]}}]}
        processes = Processes(domain)
        deadline = time.monotonic() + 10
        while processes.update(snapshot)["/talker"].pid is None and time.monotonic() < deadline:
            time.sleep(0.2)
        usage = processes.usage["/talker"]
        assert usage.pid == talker[0].pid and usage.rss and usage.rss > 1_000_000
    finally:
        stop_all(talker)
