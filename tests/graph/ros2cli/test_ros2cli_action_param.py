"""ros2action's CLI tests and ros2param's test_verb_dump/list/load (ros2cli 0.32.2), ported: each case runs
against roc and against the real ros2 (tests/helpers/ros2cli.py says how). The two share one graph (the
fibonacci action server, and /foo/test_node, started afresh for each tool's phase: the load cases
change its parameters, and the dump case expects the ones it started with)."""

from __future__ import annotations

import re

import pytest
import yaml
from helpers.graph import graph_env
from helpers.ros2cli import TOOLS, Cli, FixtureGraph, expect_lines, oracle, retry, tool_phase

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("ros2cli_action_param")]
__all__ = ["oracle"]

TEST_NODE = "/foo/test_node"
# the parameters of ros2param's fixture node, as param dump writes them
PARAMETER_FILE = """\
/foo/test_node:
  ros__parameters:
    bool_array_param:
    - {bool_array}
    bool_param: {bool}
    double_array_param:
    - {double_array}
    double_param: {double}
    foo:
      bar:
        str_param: {foo_bar}
      str_param: {foo}
    int_array_param:
    - {int_array}
    int_param: {int}
    start_type_description_service: true
    str_array_param:
    - {str_array}
    str_param: {str}
    use_sim_time: false
"""


def parameter_file(**values) -> str:
    return PARAMETER_FILE.format(**{key: "\n    - ".join(value) if isinstance(value, list) else value
                                    for key, value in values.items()})


EXPECTED_PARAMETER_FILE = parameter_file(
    bool_array=["false", "false", "true"], bool="true", double_array=["3.125", "6.25", "12.5"], double="1.23",
    foo_bar="foobar", foo="foo", int_array=["1", "2", "3"], int="42", str_array=["foo", "bar", "baz"],
    str="Hello World")
INPUT_PARAMETER_FILE = parameter_file(
    bool_array=["true", "false", "false"], bool="false", double_array=["2.125", "1.25", "2.5"], double="1.3",
    foo_bar="foo_bar", foo="foobar", int_array=["42", "3", "3"], int="-42", str_array=["a_foo", "a_bar", "baz"],
    str="Bye World")
INPUT_WILDCARD_PARAMETER_FILE = "/**:\n  ros__parameters:\n    str_param: Wildcard\n    int_param: 12345\n"
INPUT_NODE_OVERLAY_PARAMETER_FILE = "/foo/test_node:\n  ros__parameters:\n    str_param: Override\n"


@pytest.fixture(scope="module")
def graph(tmp_path_factory, oracle):  # noqa: F811
    with FixtureGraph(graph_env(23, tmp_path_factory.mktemp("runtime"))) as graph:
        graph.start("fibonacci_action_server")
        yield graph


def _discovered(cli: Cli) -> bool:
    """The action server is known, and /foo/test_node's parameter services (upstream's setUp)."""
    actions = cli.run("action", "list").output.splitlines()
    services = cli.run("service", "list").output.splitlines()
    return "/fibonacci" in actions and f"{TEST_NODE}/list_parameters" in services \
        and f"{TEST_NODE}/get_parameters" in services


@pytest.fixture(scope="module", params=TOOLS)
def cli(request, graph) -> Cli:
    graph.start("parameter_node", name="test_node", namespace="/foo")
    yield tool_phase(request.param, graph.env, _discovered)
    graph.stop("test_node")


# -- ros2action ---------------------------------------------------------------------------------------

def send_goal_output(order: int = 1, with_feedback: int = 0) -> list:
    """What ``action send_goal`` prints for a Fibonacci goal of ``order`` (``with_feedback``: that many
    feedback messages are expected)."""
    output = ["Waiting for an action server to become available...", "Sending goal:", f"     order: {order}", "",
              re.compile("Goal accepted with ID: [a-f0-9]+"), ""]
    sequence = [0, 1]
    for _ in range(order - 1):
        sequence.append(sequence[-1] + sequence[-2])
        if with_feedback > 0:
            output += ["Feedback:", *("    " + yaml.dump({"sequence": sequence})).splitlines(), ""]
            with_feedback -= 1
    output += ["Result:", *("    " + yaml.dump({"sequence": sequence})).splitlines(), "",
               "Goal finished with status: SUCCEEDED"]
    return output


def test_info_on_nonexistent_action(cli):
    result = cli.run("action", "info", "/not_an_action")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["Action: /not_an_action", "Action clients: 0", "Action servers: 0"]), \
        result.output


@retry(5)
def test_fibonacci_info(cli):
    result = cli.run("action", "info", "/fibonacci")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["Action: /fibonacci", "Action clients: 0", "Action servers: 1",
                                        "  /fibonacci_action_server"]), result.output


@retry(5)
def test_fibonacci_info_with_types(cli):
    result = cli.run("action", "info", "-t", "/fibonacci")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["Action: /fibonacci", "Action clients: 0", "Action servers: 1",
                                        "  /fibonacci_action_server [test_msgs/action/Fibonacci]"]), result.output


@retry(5)
def test_fibonacci_info_count(cli):
    result = cli.run("action", "info", "-c", "/fibonacci")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["Action: /fibonacci", "Action clients: 0", "Action servers: 1"]), \
        result.output


@retry(5)
def test_list(cli):
    result = cli.run("action", "list")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/fibonacci"], strict=True), result.output


@retry(5)
def test_list_with_types(cli):
    result = cli.run("action", "list", "-t")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/fibonacci [test_msgs/action/Fibonacci]"], strict=True), result.output


@retry(5)
def test_list_count(cli):
    result = cli.run("action", "list", "-c")
    assert result.exit_code == 0
    assert [int(line) for line in result.output.splitlines()] == [1]


@retry(5)
def test_type(cli):
    result = cli.run("action", "type", "/fibonacci")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["test_msgs/action/Fibonacci"], strict=True), result.output


@retry(5)
def test_send_fibonacci_goal(cli):
    result = cli.run("action", "send_goal", "/fibonacci", "test_msgs/action/Fibonacci", "{order: 5}")
    assert result.exit_code == 0
    assert expect_lines(result.output, send_goal_output(order=5), strict=True), result.output


@retry(5)
def test_send_fibonacci_goal_with_feedback(cli):
    result = cli.run("action", "send_goal", "-f", "/fibonacci", "test_msgs/action/Fibonacci", "{order: 5}")
    assert result.exit_code == 0
    assert expect_lines(result.output, send_goal_output(order=5, with_feedback=1)), result.output


# -- ros2param: test_verb_dump.py (first: it expects the parameters the node started with) -------------

def test_verb_dump_invalid_node(cli):
    for node in ("invalid_node", "invalid_ns/test_node"):
        result = cli.run("param", "dump", node, timeout=20)
        assert result.exit_code != 0
        assert expect_lines(result.output, ["Node not found"], strict=True), result.output


def test_verb_dump(cli):
    result = cli.run("param", "dump", TEST_NODE, timeout=20)
    assert result.exit_code == 0
    assert result.output == EXPECTED_PARAMETER_FILE + "\n"


# -- ros2param: test_verb_list.py ---------------------------------------------------------------------

def test_verb_list_invalid_node(cli):
    for node in ("invalid_node", "invalid_ns/test_node"):
        result = cli.run("param", "list", node, timeout=20)
        assert result.exit_code != 0
        assert expect_lines(result.output, ["Node not found"], strict=True), result.output


@retry(5)
def test_verb_list(cli):
    result = cli.run("param", "list", TEST_NODE, timeout=20)
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "  bool_array_param", "  bool_param", "  double_array_param", "  double_param", "  foo.bar.str_param",
        "  foo.str_param", "  int_array_param", "  int_param", "  start_type_description_service",
        "  str_array_param", "  str_param", "  use_sim_time"], strict=True), result.output


@retry(5)
def test_verb_list_filter(cli):
    result = cli.run("param", "list", TEST_NODE, "--filter", "bool.*", timeout=20)
    assert result.exit_code == 0
    assert expect_lines(result.output, ["  bool_array_param", "  bool_param"], strict=True), \
        f"actual output: {result.output}"


# -- ros2param: test_verb_load.py ---------------------------------------------------------------------

def test_verb_load_missing_args(cli):
    result = cli.run("param", "load", timeout=20)
    assert result.exit_code != 0
    assert expect_lines(result.output, [f"{cli.tool} param load: error: the following arguments are required: "
                                        "node_name, parameter_file"]), result.output
    result = cli.run("param", "load", "some_node", timeout=20)
    assert result.exit_code != 0
    assert expect_lines(result.output, [f"{cli.tool} param load: error: the following arguments are required: "
                                        "parameter_file"]), result.output


def _write(tmp_path, contents: str) -> str:
    path = tmp_path / "params.yaml"
    path.write_text(contents)
    return str(path)


def test_verb_load_invalid_node(cli, tmp_path):
    path = _write(tmp_path, INPUT_PARAMETER_FILE)
    for node in ("invalid_node", "invalid_ns/test_node"):
        result = cli.run("param", "load", node, path, timeout=20)
        assert result.exit_code != 0
        assert expect_lines(result.output, ["Node not found"], strict=True), result.output


def test_verb_load_invalid_path(cli):
    result = cli.run("param", "load", TEST_NODE, "invalid_path", timeout=20)
    assert result.exit_code != 0
    assert expect_lines(result.output, ["No such file or directory"]), result.output


def test_verb_load_timeout(cli):
    result = cli.run("param", "load", "invalid_node", "invalid_path", "--timeout", "2", timeout=20)
    assert result.exit_code != 0
    assert expect_lines(result.output, ["Node not found"]), result.output


def _dumped(cli: Cli) -> dict:
    result = cli.run("param", "dump", TEST_NODE, timeout=20)
    assert result.exit_code == 0
    return yaml.safe_load(result.output)[TEST_NODE]["ros__parameters"]


def test_verb_load(cli, tmp_path):
    path = _write(tmp_path, INPUT_PARAMETER_FILE)
    result = cli.run("param", "load", TEST_NODE, path, "--timeout", "3", timeout=20)
    assert result.exit_code == 0
    assert expect_lines(result.output, [""], strict=True), result.output
    dumped = cli.run("param", "dump", TEST_NODE, timeout=20)
    assert dumped.exit_code == 0
    assert dumped.output == INPUT_PARAMETER_FILE + "\n"


def test_verb_load_wildcard(cli, tmp_path):
    path = _write(tmp_path, INPUT_WILDCARD_PARAMETER_FILE)
    result = cli.run("param", "load", TEST_NODE, path, "--no-use-wildcard", "--timeout", "3", timeout=20)
    assert result.exit_code != 0
    assert expect_lines(result.output, ["Param file does not contain selected parameters"]), result.output

    result = cli.run("param", "load", TEST_NODE, path, timeout=20)
    assert result.exit_code == 0
    assert expect_lines(result.output, [""], strict=True), result.output
    params = _dumped(cli)
    assert (params["str_param"], params["int_param"]) == ("Wildcard", 12345)

    path = _write(tmp_path, INPUT_WILDCARD_PARAMETER_FILE + "\n" + INPUT_NODE_OVERLAY_PARAMETER_FILE)
    result = cli.run("param", "load", TEST_NODE, path, timeout=20)
    assert result.exit_code == 0
    params = _dumped(cli)
    assert (params["str_param"], params["int_param"]) == ("Override", 12345)  # the node's own entry wins
