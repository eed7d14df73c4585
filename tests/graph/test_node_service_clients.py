"""The clients a Graph calls nodes' own services with (parameters, type description: roc.ros.graph.
Graph.call_node_service): kept for later calls, at most KEPT_CLIENTS of them, and left out of roc's
answers as roc's own nodes are. Why: a server on Cyclone DDS answers a client new to it only once it
has discovered it, polling every 10 ms, so a fresh client made every param get through the daemon 11 ms
slower than on Fast DDS."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, start_nodes, stop_all, stop_daemon

from roc.middleware import process_environment

pytestmark = [pytest.mark.slow, pytest.mark.rmw]

SLOT = 57
NODES = [{"name": "motor", "parameters": {"max_speed": 1.5}}, {"name": "arm", "parameters": {"reach": 0.8}}]

SCRIPT = r'''
import json
import roc.ros.graph as graph_module
from roc.ros.graph import Graph

graph_module.KEPT_CLIENTS = 2
graph = Graph()
graph.wait_for_discovery()

def clients():
    return sorted(client.srv_name for client in graph.node.clients)

first = graph.param_values("/motor", ["max_speed"])
kept = [id(client) for client in graph.node.clients]
again = graph.param_values("/motor", ["max_speed"])
after_two_gets = (clients(), [id(client) for client in graph.node.clients] == kept)
graph.param_names("/motor")
graph.param_values("/arm", ["reach"])  # a third service: the one used longest ago goes
print(json.dumps({"values": [first, again], "after_two_gets": after_two_gets, "after_three": clients()}))
graph.close()
'''


def test_a_parameter_service_s_client_is_kept_for_the_next_call_and_only_the_latest_few(tmp_path: Path) -> None:
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([NODES], env)
    try:
        done = subprocess.run([sys.executable, "-c", SCRIPT], env=process_environment(env), capture_output=True,
                              text=True, timeout=120)
    finally:
        stop_all(processes)
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert seen["values"] == [[{"type": "double", "value": 1.5}]] * 2
    assert seen["after_two_gets"] == [["/motor/get_parameters"], True]  # one client, the same both times
    assert seen["after_three"] == ["/arm/get_parameters", "/motor/list_parameters"]


def test_service_info_leaves_out_the_daemon_s_kept_client(tmp_path: Path) -> None:
    env = graph_env(SLOT, tmp_path)
    processes = start_nodes([NODES], env)
    try:
        got = roc("param", "get", "/motor", "max_speed", env=env)  # through the daemon, which keeps its client
        assert got.returncode == 0, got.stderr
        info = roc("service", "info", "/motor/get_parameters", "--format", "json", "-v", env=env)
    finally:
        stop_daemon(env)
        stop_all(processes)
    assert info.returncode == 0, info.stderr
    data = json.loads(info.stdout)
    assert (data["clients_count"], data["clients"], data["services_count"]) == (0, [], 1)
