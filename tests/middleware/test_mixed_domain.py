"""A domain where Fast DDS and Cyclone DDS processes meet: roc on Cyclone DDS sends no service request to a
Fast DDS node, which such a request can crash (ros2/rmw_cyclonedds#577: Jazzy's rmw_fastrtps reads the
request's header as a sequence length): param list leaves the node out and says so in one line, param get
and service call refuse it in one line; the node lives on, and roc on Fast DDS asks it as always."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, start_nodes, stop_all, stop_daemon, wait_for
from helpers.rmw import CYCLONEDDS, FASTRTPS, on_middleware, require_cyclonedds

from roc.ros import vendors

SLOT = 48
REASON = "a Cyclone DDS request can crash a Fast DDS node (ros2/rmw_cyclonedds#577)"


def test_a_request_is_refused_only_from_cyclone_dds_to_fast_dds() -> None:
    fast, cyclone = b"\x01\x0f" + bytes(14), b"\x01\x10" + bytes(14)
    assert vendors.request_crash("rmw_cyclonedds_cpp", fast) == REASON
    assert vendors.request_crash("rmw_cyclonedds_cpp", cyclone) is None
    assert vendors.request_crash("rmw_fastrtps_cpp", cyclone) is None
    assert vendors.request_crash("rmw_fastrtps_cpp", fast) is None


@pytest.mark.slow
def test_roc_on_cyclone_dds_sends_no_request_to_a_fast_dds_node(tmp_path: Path) -> None:
    require_cyclonedds()
    env = graph_env(SLOT, tmp_path)
    on_fast, on_cyclone = on_middleware(env, FASTRTPS), on_middleware(env, CYCLONEDDS)
    fast = start_nodes([{"name": "fast", "parameters": {"speed": 1.5},
                         "services": [{"name": "~/reset", "type": "std_srvs/srv/Trigger"}]}], on_fast)
    cyclone = start_nodes([{"name": "cyc", "parameters": {"gain": 2.0}}], on_cyclone)
    try:
        wait_for(lambda: {"/fast", "/cyc"} <= set(roc("node", "list", env=on_cyclone).stdout.split()))
        listed = roc("param", "list", env=on_cyclone)
        assert listed.returncode == 0, listed.stderr
        assert "/cyc:\n" in listed.stdout and "/fast:" not in listed.stdout
        assert listed.stderr == f"roc: warning: left out /fast: {REASON}; ask from a process on its middleware " \
                                "(RMW_IMPLEMENTATION=rmw_fastrtps_cpp)\n"
        got = roc("param", "get", "/fast", "speed", env=on_cyclone)
        assert got.returncode == 1 and f"/fast: not asked: {REASON}" in got.stderr
        assert len(got.stderr.splitlines()) == 1
        called = roc("service", "call", "/fast/reset", "std_srvs/srv/Trigger", env=on_cyclone)
        assert called.returncode == 1 and f"/fast: not asked: {REASON}" in called.stderr
        assert roc("param", "get", "/cyc", "gain", env=on_cyclone).stdout == "Double value is: 2.0\n"
        # from Fast DDS, the node is asked as always, and it lives
        assert roc("param", "get", "/fast", "speed", env=on_fast).stdout == "Double value is: 1.5\n"
        assert fast[0].poll() is None
    finally:
        stop_daemon(on_cyclone)
        stop_daemon(on_fast)
        stop_all([*fast, *cyclone])


def test_doctor_reports_a_mixed_domain() -> None:
    from roc.doctor.live_graph import middlewares

    def ask(gids):
        return lambda method, params: {"publishers": [{"gid": gid} for gid in gids]}
    fast, cyclone = "01.0f.7f.01.f3.5f.00.00.01.00.00.00.00.00.01.03", "01.10.45.12.ab.cd.00.00.01.00.00.00.00.00.01.03"
    assert middlewares(ask([fast, fast])).message == "every node on Fast DDS"
    mixed = middlewares(ask([fast, cyclone, fast]))
    assert mixed.level == "warning"
    assert mixed.message.startswith("a mixed domain: 1 node(s) on Cyclone DDS, 2 node(s) on Fast DDS; ")
