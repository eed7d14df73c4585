"""ros2service's CLI tests (ros2cli 0.32.2, test/test_cli.py), ported: each case runs against roc and against
the real ros2 on the upstream fixture graph (tests/helpers/ros2cli.py says how)."""

from __future__ import annotations

import pytest
from helpers.graph import graph_env
from helpers.ros2cli import TOOLS, Cli, FixtureGraph, expect_lines, oracle, output_filter, retry, tool_phase

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("ros2cli_service")]
__all__ = ["oracle"]

SERVICE_FILTER = output_filter(prefixes=["waiting for service to become available...", "/launch_ros"])
BUILTIN_SERVICES = {
    "describe_parameters": "rcl_interfaces/srv/DescribeParameters",
    "get_parameter_types": "rcl_interfaces/srv/GetParameterTypes",
    "get_parameters": "rcl_interfaces/srv/GetParameters",
    "get_type_description": "type_description_interfaces/srv/GetTypeDescription",
    "list_parameters": "rcl_interfaces/srv/ListParameters",
    "set_parameters": "rcl_interfaces/srv/SetParameters",
    "set_parameters_atomically": "rcl_interfaces/srv/SetParametersAtomically",
}


def builtin_services(namespace: str, with_types: bool = False) -> list[str]:
    return [f"{namespace}/{name}" + (f" [{type_name}]" if with_types else "")
            for name, type_name in BUILTIN_SERVICES.items()]


def echo_call_output(**fields) -> list[str]:
    """What ``service call /my_ns/echo`` prints for a request of ``fields``: the request's and the
    response's repr (the echo server answers with the request's fields)."""
    from test_msgs.srv import BasicTypes

    request, response = BasicTypes.Request(**fields), BasicTypes.Response(**fields)
    return ["requester: making request: " + repr(request), "", "response:", repr(response), ""]


@pytest.fixture(scope="module")
def graph(tmp_path_factory, oracle):  # noqa: F811
    """/my_ns/echo_server, and the same server hidden (/my_ns/_hidden_echo_server serving _echo)."""
    with FixtureGraph(graph_env(22, tmp_path_factory.mktemp("runtime"))) as graph:
        graph.start("echo_server", name="echo_server", namespace="my_ns")
        graph.start("echo_server", name="_hidden_echo_server", namespace="my_ns", remap=[("echo", "_echo")])
        yield graph


def _discovered(cli: Cli) -> bool:
    services = cli.run("service", "list", "--include-hidden-services").output.splitlines()
    return {"/my_ns/_echo", "/my_ns/echo", *builtin_services("/my_ns/echo_server"),
            *builtin_services("/my_ns/_hidden_echo_server")} <= set(services)


@pytest.fixture(scope="module", params=TOOLS)
def cli(request, graph) -> Cli:
    return tool_phase(request.param, graph.env, _discovered, SERVICE_FILTER)


@retry(5)
def test_list_services(cli):
    result = cli.run("service", "list")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/my_ns/echo", *builtin_services("/my_ns/echo_server")], strict=True), \
        result.output


@retry(5)
def test_list_hidden(cli):
    result = cli.run("service", "list", "--include-hidden-services")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/my_ns/_echo", *builtin_services("/my_ns/_hidden_echo_server"),
                                        "/my_ns/echo", *builtin_services("/my_ns/echo_server")], strict=True), \
        result.output


@retry(5)
def test_list_with_types(cli):
    result = cli.run("service", "list", "-t")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/my_ns/echo [test_msgs/srv/BasicTypes]",
                                        *builtin_services("/my_ns/echo_server", with_types=True)], strict=True), \
        result.output


@retry(5)
def test_list_count(cli):
    result = cli.run("service", "list", "-c")
    assert result.exit_code == 0
    assert [int(line) for line in result.output.splitlines()] == [len(BUILTIN_SERVICES) + 1]


@retry(5)
def test_find(cli):
    result = cli.run("service", "find", "test_msgs/srv/BasicTypes")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/my_ns/echo"], strict=True), result.output


@retry(5)
def test_find_hidden(cli):
    result = cli.run("service", "find", "--include-hidden-services", "test_msgs/srv/BasicTypes")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/my_ns/_echo", "/my_ns/echo"], strict=True), result.output


@retry(5)
def test_find_count(cli):
    result = cli.run("service", "find", "-c", "test_msgs/srv/BasicTypes")
    assert result.exit_code == 0
    assert [int(line) for line in result.output.splitlines()] == [1]


def test_find_not_a_service_type(cli):
    result = cli.run("service", "find", "not_a_service_type")
    assert result.exit_code == 0
    assert result.output == ""


def test_type(cli):
    result = cli.run("service", "type", "/my_ns/echo")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["test_msgs/srv/BasicTypes"], strict=True), result.output


def test_type_on_not_a_service(cli):
    result = cli.run("service", "type", "/not_a_service")
    assert result.exit_code == 1
    # ros2 prints nothing; roc's stdout is as empty, and it says why on stderr (a deliberate difference)
    assert result.output == ("" if cli.tool == "ros2" else "roc: error: Unknown service '/not_a_service'\n")


@retry(5)
def test_call_no_args(cli):
    result = cli.run("service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes")
    assert result.exit_code == 0
    assert expect_lines(result.output, echo_call_output(), strict=True), result.output


@retry(5)
def test_call(cli):
    result = cli.run("service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes",
                     "{bool_value: false, int32_value: -1, float64_value: 0.1, string_value: bazbar}")
    assert result.exit_code == 0
    assert expect_lines(result.output, echo_call_output(bool_value=False, int32_value=-1, float64_value=0.1,
                                                        string_value="bazbar"), strict=True), result.output


@retry(5)
def test_repeated_call(cli):
    with cli.stream("service", "call", "-r", "1", "/my_ns/echo", "test_msgs/srv/BasicTypes",
                    "{bool_value: true, int32_value: 1, float64_value: 1.0, string_value: foobar}") as command:
        assert command.wait_for_output(2 * echo_call_output(bool_value=True, int32_value=1, float64_value=1.0,
                                                            string_value="foobar"), timeout=10), command.output
