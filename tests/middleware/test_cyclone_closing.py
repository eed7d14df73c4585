"""roc's one-shot verbs on Cyclone DDS close their participant without waiting for its last messages to be
acknowledged (roc.ros.vendors.cyclonedds.close_at_once): the setting joins the user's Cyclone configuration
for that participant alone, and a parameter change asked without the daemon still takes effect."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, start_nodes, stop_all, wait_for
from helpers.rmw import CYCLONEDDS, on_middleware, require_cyclonedds

from roc.ros.vendors.cyclonedds import NO_LINGER, close_at_once

SLOT = 51


@pytest.mark.parametrize(("environment", "expected"), [
    ({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, NO_LINGER),
    ({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp", "CYCLONEDDS_URI": "file:///etc/cyclone.xml"},
     f"file:///etc/cyclone.xml,{NO_LINGER}"),  # after the user's, which Cyclone reads first
    ({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp", "CYCLONEDDS_URI": "<Internal><WriterLingerDuration>2s"
      "</WriterLingerDuration></Internal>"}, "<Internal><WriterLingerDuration>2s</WriterLingerDuration></Internal>"),
    ({"RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}, None),
])
def test_only_a_cyclone_participant_is_told_not_to_linger(environment: dict[str, str], expected: str | None) -> None:
    before = dict(environment)
    with close_at_once(environment):
        assert environment.get("CYCLONEDDS_URI") == expected
    assert environment == before  # the participants made later (a publisher's) linger as Cyclone's do


@pytest.mark.rmw
@pytest.mark.slow
def test_queries_without_the_daemon_keep_the_users_configuration_and_their_requests_take_effect(tmp_path: Path) -> None:
    require_cyclonedds()
    config = tmp_path / "cyclone.xml"
    config.write_text('<?xml version="1.0" encoding="UTF-8"?><CycloneDDS><Domain id="any"><Discovery>'
                      "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>100</MaxAutoParticipantIndex>"
                      "</Discovery></Domain></CycloneDDS>")
    env = on_middleware(graph_env(SLOT, tmp_path, CYCLONEDDS_URI=config.as_uri()), CYCLONEDDS)
    nodes = start_nodes([{"name": "cyc", "parameters": {"gain": 2.0}}], env)
    try:
        wait_for(lambda: "/cyc" in roc("node", "list", "--no-daemon", env=env).stdout.split())
        changed = roc("param", "set", "/cyc", "gain", "3.5", "--no-daemon", env=env)
        assert changed.returncode == 0 and changed.stdout == "Set parameter successful\n", changed.stderr
        assert roc("param", "get", "/cyc", "gain", "--no-daemon", env=env).stdout == "Double value is: 3.5\n"
    finally:
        stop_all(nodes)
