"""ros2topic's CLI tests (ros2cli 0.32.2, test/test_cli.py), ported: each case runs against roc and against
the real ros2 on the upstream fixture graph (tests/helpers/ros2cli.py says how). Where roc answers
differently on purpose, the case says so and docs/coming-from-ros2.md lists it."""

from __future__ import annotations

import math
import re

import pytest
from helpers.build import BIN
from helpers.graph import graph_env
from helpers.ros2cli import TOOLS, Cli, FixtureGraph, Stream, expect_lines, oracle, output_filter, retry, tool_phase

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("ros2cli_topic")]
__all__ = ["oracle"]

TOPICS = ["/arrays", "/bounded_sequences", "/chatter", "/chit_chatter", "/cmd_vel", "/defaults", "/parameter_events",
          "/rosout", "/unbounded_sequences"]
ECHO_FILTER = output_filter(patterns=["WARNING: topic .* does not appear to be published yet"])
STATS_LINE = re.compile(r"\s*min: \d+.\d{3}s max: \d+.\d{3}s std dev: \d+.\d{5}s window: \d+")


@pytest.fixture(scope="module")
def graph(tmp_path_factory, oracle):  # noqa: F811
    """talker and listener (on chit_chatter), a hidden talker, four repeaters and the controller."""
    with FixtureGraph(graph_env(20, tmp_path_factory.mktemp("runtime"))) as graph:
        graph.start("talker")
        graph.start("listener", remap=[("chatter", "chit_chatter")])
        graph.start("talker", remap=[("chatter", "_hidden_chatter")], key="hidden_talker")
        for type_name, name, topic in (("Arrays", "array_repeater", "/arrays"),
                                       ("Defaults", "defaults_repeater", "/defaults"),
                                       ("BoundedSequences", "bounded_sequences_repeater", "/bounded_sequences"),
                                       ("UnboundedSequences", "unbounded_sequences_repeater", "/unbounded_sequences")):
            graph.start("repeater", f"test_msgs/msg/{type_name}", name=name, remap=[(f"/{name}/output", topic)])
        graph.start("controller")
        yield graph


NODES = ["/talker_node", "/talker_node", "/listener", "/array_repeater", "/defaults_repeater",
         "/bounded_sequences_repeater", "/unbounded_sequences_repeater", "/controller"]


def _discovered(cli: Cli) -> bool:
    """Every fixture node and topic (the hidden talker's too) is known."""
    nodes = cli.run("node", "list").output.splitlines()
    topics = cli.run("topic", "list", "--include-hidden-topics").output.splitlines()
    return sorted(n for n in nodes if n in NODES) == sorted(NODES) and set(TOPICS) <= set(topics) \
        and "/_hidden_chatter" in topics


@pytest.fixture(scope="module", params=TOOLS)
def cli(request, graph) -> Cli:
    return tool_phase(request.param, graph.env, _discovered, ECHO_FILTER)


def own_nodes(cli: Cli) -> int:
    """The CLI's own nodes in the graph's counts: ros2 counts its daemon's node (upstream's "9
    publishers" are 8 fixtures and it); roc never counts its own participants (a deliberate difference)."""
    return 1 if cli.tool == "ros2" else 0


@retry(5)
def test_list_topics(cli):
    result = cli.run("topic", "list")
    assert result.exit_code == 0
    assert expect_lines(result.output, TOPICS, strict=True), result.output


@retry(5)
def test_list_all_topics(cli):
    result = cli.run("topic", "list", "--include-hidden-topics")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/_hidden_chatter", *TOPICS], strict=True), result.output


@retry(5)
def test_list_with_types(cli):
    result = cli.run("topic", "list", "-t")
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "/arrays [test_msgs/msg/Arrays]", "/bounded_sequences [test_msgs/msg/BoundedSequences]",
        "/chatter [std_msgs/msg/String]", "/chit_chatter [std_msgs/msg/String]",
        "/cmd_vel [geometry_msgs/msg/TwistStamped]", "/defaults [test_msgs/msg/Defaults]",
        "/parameter_events [rcl_interfaces/msg/ParameterEvent]", "/rosout [rcl_interfaces/msg/Log]",
        "/unbounded_sequences [test_msgs/msg/UnboundedSequences]"], strict=True), result.output


@retry(5)
def test_list_with_verbose(cli):
    nodes = 8 + own_nodes(cli)
    result = cli.run("topic", "list", "-v")
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "Published topics:",
        " * /arrays [test_msgs/msg/Arrays] 1 publisher",
        " * /bounded_sequences [test_msgs/msg/BoundedSequences] 1 publisher",
        " * /chatter [std_msgs/msg/String] 1 publisher",
        " * /cmd_vel [geometry_msgs/msg/TwistStamped] 1 publisher",
        " * /defaults [test_msgs/msg/Defaults] 1 publisher",
        f" * /parameter_events [rcl_interfaces/msg/ParameterEvent] {nodes} publishers",
        f" * /rosout [rcl_interfaces/msg/Log] {nodes} publishers",
        " * /unbounded_sequences [test_msgs/msg/UnboundedSequences] 1 publisher",
        "",
        "Subscribed topics:",
        " * /chit_chatter [std_msgs/msg/String] 1 subscriber",
        ""], strict=True), result.output


@retry(5)
def test_list_count(cli):
    result = cli.run("topic", "list", "-c")
    assert result.exit_code == 0
    assert [int(line) for line in result.output.splitlines()] == [9]


@retry(5)
def test_topic_endpoint_info(cli):
    result = cli.run("topic", "info", "/chatter")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["Type: std_msgs/msg/String", "Publisher count: 1", "Subscription count: 0"],
                        strict=True), result.output


@retry(5)
def test_topic_endpoint_info_verbose(cli):
    string_hash = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    result = cli.run("topic", "info", "-v", "/chatter")
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "Type: std_msgs/msg/String", "", "Publisher count: 1", "",
        re.compile(r"Node name: \w+"), "Node namespace: /", "Topic type: std_msgs/msg/String",
        f"Topic type hash: {string_hash}",
        re.compile(r"Endpoint type: (INVALID|PUBLISHER|SUBSCRIPTION)"), re.compile(r"GID: [\w\.]+"), "QoS profile:",
        re.compile(r"  Reliability: (RELIABLE|BEST_EFFORT|SYSTEM_DEFAULT|UNKNOWN)"),
        re.compile(r"  History \(Depth\): (KEEP_LAST|KEEP_ALL|SYSTEM_DEFAULT|UNKNOWN)[\s\(\d\)]?"),
        re.compile(r"  Durability: (VOLATILE|TRANSIENT_LOCAL|SYSTEM_DEFAULT|UNKNOWN)"),
        "  Lifespan: Infinite", "  Deadline: Infinite",
        re.compile(r"  Liveliness: (AUTOMATIC|MANUAL_BY_TOPIC|SYSTEM_DEFAULT|UNKNOWN)"),
        "  Liveliness lease duration: Infinite", "", "Subscription count: 0", ""], strict=True), result.output


def test_info_on_unknown_topic(cli):
    result = cli.run("topic", "info", "/unknown_topic")
    assert expect_lines(result.output, ["Unknown topic '/unknown_topic'"], strict=True), result.output


@retry(5)
def test_topic_type(cli):
    result = cli.run("topic", "type", "/chatter")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["std_msgs/msg/String"], strict=True), result.output


@retry(5)
def test_hidden_topic_type(cli):
    result = cli.run("topic", "type", "/_hidden_chatter")
    assert result.exit_code == 1
    # ros2 prints nothing; roc's stdout is as empty, and it says why on stderr (a deliberate difference)
    assert result.output == ("" if cli.tool == "ros2" else "roc: error: Unknown topic '/_hidden_chatter' "
                                                           "(a hidden topic: add --include-hidden-topics)\n")


@retry(5)
def test_find_topic_type(cli):
    result = cli.run("topic", "find", "rcl_interfaces/msg/Log")
    assert result.exit_code == 0
    assert expect_lines(result.output, ["/rosout"], strict=True), result.output


def test_find_not_a_topic_typename(cli):
    result = cli.run("topic", "find", "rcl_interfaces/msg/NotAMessageTypeName")
    assert result.exit_code == 0
    assert not result.output


def echoes(cli: Cli, arguments: list[str], expected: list, strict: bool = True) -> None:
    """Upstream's echo cases: the lines within 10 s, then the command ends on SIGINT within 10 s."""
    with cli.stream("topic", "echo", *arguments) as command:
        assert command.wait_for_output(expected, strict=strict, timeout=10), command.output
    assert command.exit_code is not None


@retry(5)
def test_topic_echo(cli):
    echoes(cli, ["/chatter"], [re.compile(r"data: 'Hello World: \d+'"), "---"])


@retry(5)
def test_no_str_topic_echo(cli):
    echoes(cli, ["--no-str", "/chatter"], [re.compile(r"data: '<string length: <\d+>>'"), "---"])


@retry(5)
def test_csv_topic_echo(cli):
    echoes(cli, ["--csv", "/defaults"],
           ["True,b'2',100,1.125,1.125,-50,200,-1000,2000,-30000,60000,-40000000,50000000"])


FIELDS = [("bool", "boolean"), ("byte", "octet"), ("char", "uint8"), ("float32", "float"), ("float64", "double"),
          ("int8", "int8"), ("uint8", "uint8"), ("int16", "int16"), ("uint16", "uint16"), ("int32", "int32"),
          ("uint32", "uint32"), ("int64", "int64"), ("uint64", "uint64"), ("string", "string"),
          ("basic_types", "test_msgs/msg/BasicTypes"), ("constants", "test_msgs/msg/Constants"),
          ("defaults", "test_msgs/msg/Defaults")]


def no_arr_lines(placeholder) -> list[str]:
    """echo --no-arr's lines for test_msgs' Arrays / sequence messages: ``placeholder(type, length)`` for each
    ``*_values`` field (empty) and ``*_values_default`` field (three elements), then the last field."""
    lines = [f"{name}_values: '{placeholder(type_name, 0)}'" for name, type_name in FIELDS]
    lines += [f"{name}_values_default: '{placeholder(type_name, 3)}'" for name, type_name in FIELDS[:14]]
    return [*lines, "alignment_check: 0", "---"]


@retry(5)
def test_no_arr_topic_echo_on_array_message(cli):
    echoes(cli, ["--no-arr", "/arrays"], no_arr_lines(lambda type_name, _: f"<array type: {type_name}[3]>"),
           strict=False)


@retry(5)
def test_no_arr_topic_echo_on_seq_message(cli):
    echoes(cli, ["--no-arr", "/unbounded_sequences"],
           no_arr_lines(lambda type_name, length: f"<sequence type: {type_name}, length: {length}>"))


@retry(5)
def test_no_arr_topic_echo_on_bounded_seq_message(cli):
    echoes(cli, ["--no-arr", "/bounded_sequences"],
           no_arr_lines(lambda type_name, length: f"<sequence type: {type_name}[3], length: {length}>"))


@retry(5)
def test_truncate_length_topic_echo(cli):
    echoes(cli, ["--truncate-length", "5", "/chatter"], [re.compile(r"data: Hello..."), "---"])


@retry(5)
def test_topic_echo_field(cli):
    echoes(cli, ["/arrays", "--field", "alignment_check"], ["0", "---"])


@retry(5)
def test_topic_echo_field_nested(cli):
    echoes(cli, ["/cmd_vel", "--field", "twist.angular"], ["x: 0.0", "y: 0.0", "z: 0.0", "---"])


@retry(5)
def test_topic_echo_field_not_a_member(cli):
    echoes(cli, ["/arrays", "--field", "not_member"],
           ["Invalid field 'not_member': 'Arrays' object has no attribute 'not_member'"])


@retry(5)  # as the other echo cases: ros2 sometimes reports a message lost as its echo joins the stream
def test_topic_echo_field_invalid(cli):
    echoes(cli, ["/arrays", "--field", "/"], ["Invalid field '/': 'Arrays' object has no attribute '/'"])
    echoes(cli, ["/arrays", "--field", "."], ["Invalid field value '.'"])


def test_topic_echo_no_publisher(cli):
    result = cli.run("topic", "echo", "/this_topic_has_no_pub", timeout=2)
    assert result.exit_code not in (0, None)
    assert expect_lines(result.output, ["Could not determine the type for the passed topic"], strict=True), \
        result.output


def _heard(listener, since: int, data: str, times: int = 1) -> bool:
    name = "second_listener" if "second" in str(listener.process.args) else "listener"
    pattern = re.compile(rf"\[INFO\] \[\d+\.\d*\] \[{name}\]: I heard: \[{data}\]")
    return listener.read_until([pattern] * times, since, timeout=10)


PUB_QOS = ["--keep-alive", "3", "--qos-durability", "transient_local", "--qos-reliability", "reliable"]


def test_topic_pub(cli, graph):
    listener = graph.fixtures["listener"]
    since = listener.mark()
    with cli.stream("topic", "pub", *PUB_QOS, "/chit_chatter", "std_msgs/msg/String", "{data: foo}") as command:
        assert command.wait_for_output(["publisher: beginning loop", "publishing #1: std_msgs.msg.String(data='foo')",
                                        ""], timeout=10), command.output
        assert _heard(listener, since, "foo", times=3)
    assert command.exit_code is not None


def test_topic_pub_once(cli, graph):
    listener = graph.fixtures["listener"]
    since = listener.mark()
    with cli.stream("topic", "pub", "--once", *PUB_QOS, "/chit_chatter", "std_msgs/msg/String",
                    "{data: bar}") as command:
        assert command.wait_for_output(["publisher: beginning loop", "publishing #1: std_msgs.msg.String(data='bar')",
                                        ""], timeout=10), command.output
        assert command.wait_for_shutdown(timeout=10)
        assert _heard(listener, since, "bar")
    assert command.exit_code == 0


def test_topic_pub_once_matching_two_listeners(cli, graph):
    listener = graph.fixtures["listener"]
    since = listener.mark()
    second = graph.start("listener", name="second_listener", remap=[("chatter", "chit_chatter")])
    try:
        with cli.stream("topic", "pub", "--once", "--keep-alive", "3", "-w", "2", "--qos-durability", "transient_local",
                        "--qos-reliability", "reliable", "/chit_chatter", "std_msgs/msg/String",
                        "{data: bar}") as command:
            assert command.wait_for_output(["publisher: beginning loop",
                                            "publishing #1: std_msgs.msg.String(data='bar')", ""], timeout=10), \
                command.output
            assert command.wait_for_shutdown(timeout=10)
            assert _heard(listener, since, "bar")
            assert _heard(second, 0, "bar")
        assert command.exit_code == 0
    finally:
        graph.stop("second_listener")


def test_topic_pub_print_every_two(cli, graph):
    listener = graph.fixtures["listener"]
    since = listener.mark()
    with cli.stream("topic", "pub", "-p", "2", *PUB_QOS, "/chit_chatter", "std_msgs/msg/String",
                    "{data: fizz}") as command:
        assert command.wait_for_output(["publisher: beginning loop", "publishing #2: std_msgs.msg.String(data='fizz')",
                                        "", "publishing #4: std_msgs.msg.String(data='fizz')", ""], timeout=10), \
            "Output does not match: " + command.output
        assert _heard(listener, since, "fizz")
    assert command.exit_code is not None


def measures(cli: Cli, arguments: list[str], head: re.Pattern) -> float:
    """hz and delay: the two lines within 10 s, the end on SIGINT; the first line's value."""
    with cli.stream("topic", *arguments) as command:
        assert command.wait_for_output([head, STATS_LINE], strict=True, timeout=10), \
            "Output does not match: " + command.output
    assert command.exit_code is not None
    return float(head.match(command.output.splitlines()[0]).group(1))


@retry(5)
def test_topic_delay(cli):
    delay = measures(cli, ["delay", "/cmd_vel"], re.compile(r"average delay: (\d+.\d{3})"))
    assert math.isclose(delay, 0.0, abs_tol=10e-3)


@retry(5)
def test_topic_hz(cli):
    rate = measures(cli, ["hz", "/chatter"], re.compile(r"average rate: (\d+.\d{3})"))
    assert math.isclose(rate, 1., rel_tol=1e-2)


@retry(5)
def test_filtered_topic_hz(cli):
    rate = measures(cli, ["hz", "--filter", 'int(m.data.rpartition(":")[-1]) % 2 == 0', "/chatter"],
                    re.compile(r"average rate: (\d+.\d{3})"))
    assert math.isclose(rate, 0.5, rel_tol=1e-2)


@retry(5)
def test_topic_bw(cli):
    with cli.stream("topic", "bw", "/defaults") as command:
        assert command.wait_for_output([
            "Subscribed to [/defaults]", re.compile(r"\d{2} B/s from \d+ messages"),
            re.compile(r"\s*Message size mean: \d{2} B min: \d{2} B max: \d{2} B")], strict=True, timeout=10), \
            command.output
    assert command.exit_code is not None


# -- roc's own regression tests on the same graph (issue 28) -------------------------------------------

@pytest.mark.parametrize("flags", [[], ["--no-daemon"]], ids=["daemon", "no-daemon"])
def test_roc_lists_and_counts_none_of_its_own_participants(graph, flags):
    """Not its daemon's node, nor the subscription a `roc topic echo` has in it, nor a daemon-less
    participant: in node, service and topic listings and counts, with and without the daemon."""
    roc = Cli("roc", graph.env)
    with roc.stream("topic", "echo", "/chatter") as echo:  # its subscription lives in roc's daemon
        assert echo.wait_for_output([re.compile(r"data: 'Hello World: \d+'")], timeout=20), echo.output
        nodes = [line for line in roc.run("node", "list", "-a", *flags, timeout=20).output.splitlines()
                 if line.startswith("/") and not line.startswith("/_ros2cli_daemon")]  # ros2's may run
        assert sorted(nodes) == sorted(NODES), nodes
        services = roc.run("service", "list", "--include-hidden-services", *flags, timeout=20).output
        assert "/_roc_" not in services
        info = roc.run("topic", "info", "/chatter", *flags, timeout=20).output
        assert "Publisher count: 1" in info and "Subscription count: 0" in info, info
        listed = roc.run("topic", "list", "-v", *flags, timeout=20).output
        assert " * /chatter [std_msgs/msg/String] 1 publisher\n" in listed
        assert "/chatter" not in listed.split("Subscribed topics:")[1], listed


def test_roc_hz_filter_counts_only_what_passes_and_loses_nothing(graph):
    """The rate of the messages that pass (every second one of a 1 Hz topic: 0.5), and no "message(s)
    lost" for those the filter left out."""
    command = Stream([str(BIN / "roc"), "topic", "hz", "--filter", 'int(m.data.rpartition(":")[-1]) % 2 == 0',
                      "/chatter"], graph.env, lambda text: text)
    try:
        assert command.wait_for_output([re.compile(r"average rate: 0\.500"), STATS_LINE] * 2, timeout=20), \
            command.output
    finally:
        command.stop()
    assert "lost" not in command.output, command.output
