"""ros2node's CLI tests (ros2cli 0.32.2, test/test_cli.py), ported: each case runs against roc and against the
real ros2 on the upstream fixture graph (tests/helpers/ros2cli.py says how)."""

from __future__ import annotations

import re

import pytest
from helpers.graph import graph_env
from helpers.ros2cli import TOOLS, Cli, FixtureGraph, expect_lines, oracle, output_filter, retry, tool_phase

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("ros2cli_node")]
__all__ = ["oracle"]

# upstream's filter: the lines of launch_ros's node and of the ros2 daemon's node
NODE_FILTER = output_filter(patterns=[".*launch_ros.*", ".*ros2cli.*"])


@pytest.fixture(scope="module")
def graph(tmp_path_factory, oracle):  # noqa: F811
    """complex_node, and the same node hidden (_hidden_complex_node)."""
    with FixtureGraph(graph_env(21, tmp_path_factory.mktemp("runtime"))) as graph:
        graph.start("complex_node", name="complex_node")
        graph.start("complex_node", name="_hidden_complex_node")
        yield graph


def _discovered(cli: Cli) -> bool:
    """Both nodes are known, with their action servers."""
    nodes = cli.run("node", "list", "-a").output.splitlines()
    actions = cli.run("node", "info", "/_hidden_complex_node", "--include-hidden").output
    return {"/complex_node", "/_hidden_complex_node"} <= set(nodes) and "/fibonacci: " in actions


@pytest.fixture(scope="module", params=TOOLS)
def cli(request, graph) -> Cli:
    return tool_phase(request.param, graph.env, _discovered, NODE_FILTER)


@retry(5)
def test_list_nodes(cli):
    result = cli.run("node", "list")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/complex_node"], strict=True), result.output


@retry(5)
def test_list_all_nodes(cli):
    result = cli.run("node", "list", "-a")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/_hidden_complex_node", "/complex_node"], strict=True), result.output


@retry(5)
def test_list_node_count(cli):
    result = cli.run("node", "list", "-c")
    assert result.exit_code == 0
    assert [int(line) for line in result.output.splitlines()] == [1]  # the fixture nodes that are not hidden


@retry(5)
def test_list_all_nodes_count(cli):
    result = cli.run("node", "list", "-c", "-a")
    assert result.exit_code == 0
    # upstream: every fixture node plus the ros2 daemon's node; roc never counts its own participants
    # (a deliberate difference)
    assert [int(line) for line in result.output.splitlines()] == [3 if cli.tool == "ros2" else 2]


PARAMETER_SERVICE = r"\s*/{node}/.*parameter.*: rcl_interfaces/srv/.*Parameter.*"


@retry(5)
def test_info_node(cli):
    result = cli.run("node", "info", "/complex_node")
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "/complex_node", "  Subscribers:", "    /strings: test_msgs/msg/Strings", "  Publishers:",
        "    /arrays: test_msgs/msg/Arrays", "    /parameter_events: rcl_interfaces/msg/ParameterEvent",
        "    /rosout: rcl_interfaces/msg/Log", "  Service Servers:", "    /basic: test_msgs/srv/BasicTypes",
        *[re.compile(PARAMETER_SERVICE.format(node="complex_node"))] * 6,
        "  Service Clients:", "", "  Action Servers:", "    /fibonacci: test_msgs/action/Fibonacci",
        "  Action Clients:", ""]), "Output does not match:\n" + result.output


@retry(5)
def test_info_hidden_node_no_hidden_flag(cli):
    result = cli.run("node", "info", "/_hidden_complex_node")
    assert result.exit_code == 1
    assert expect_lines(result.output, ["Unable to find node '/_hidden_complex_node'"], strict=True), result.output


@retry(5)
def test_info_hidden_node_hidden_flag(cli):
    result = cli.run("node", "info", "/_hidden_complex_node", "--include-hidden")
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "/_hidden_complex_node", "  Subscribers:", "    /strings: test_msgs/msg/Strings", "  Publishers:",
        "    /arrays: test_msgs/msg/Arrays", "    /parameter_events: rcl_interfaces/msg/ParameterEvent",
        "    /rosout: rcl_interfaces/msg/Log", "  Service Servers:",
        *[re.compile(PARAMETER_SERVICE.format(node="_hidden_complex_node"))] * 6,
        "    /basic: test_msgs/srv/BasicTypes", "  Service Clients:", "  Action Servers:",
        "    /fibonacci: test_msgs/action/Fibonacci", "  Action Clients:", ""]), \
        "Output does not match:\n" + result.output
