"""service info / echo, call and send_goal with --stdin, param list --include-hidden-nodes and interface show
of a type only a remote node knows: on a live graph, side by side with the ros2 CLI where it has the verb."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.build import BIN, REPO, stop_process
from helpers.graph import (
    ORACLE_VENV,
    graph_env,
    install_oracle,
    read_line,
    roc,
    ros2,
    start_nodes,
    stop_all,
    stop_daemon,
    wait_for,
)

pytestmark = pytest.mark.slow

SERVER = {"name": "motor", "services": [
    {"name": "~/enable", "type": "std_srvs/srv/SetBool"},
    {"name": "/echo_types", "type": "test_msgs/srv/BasicTypes", "echo": True, "introspection": "contents"}],
    "clients": [{"name": "/motor/enable", "type": "std_srvs/srv/SetBool"}],
    "actions": [{"name": "fibonacci"}], "parameters": {"max_speed": 1.5}}
HIDDEN = {"name": "_hidden", "parameters": {"secret": 7}}


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    reason = install_oracle()
    if reason:
        pytest.skip(f"the ros2 CLI oracle is not available: {reason}")
    env = graph_env(24, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes([[SERVER, HIDDEN]], env)
    roc("daemon", "start", env=env)
    ros2("daemon", "start", env=env)  # ros2 without its daemon misses services at times
    for tool in (roc, ros2):
        wait_for(lambda tool=tool: {"/echo_types", "/motor/enable"} <= set(tool("service", "list", env=env).stdout.split()))
    yield env
    stop_daemon(env)  # (and ros2's)
    stop_all(processes)



def test_service_info_is_ros2_s(graph):
    env = graph
    for name in ("/motor/enable", "/echo_types"):
        got, expected = roc("service", "info", name, env=env), ros2("service", "info", name, env=env)
        assert (got.returncode, got.stdout) == (expected.returncode, expected.stdout) == (0, got.stdout)
    assert roc("service", "info", "/motor/enable", env=env).stdout == \
        "Type: std_srvs/srv/SetBool\nClients count: 1\nServices count: 1\n"
    missing, expected = roc("service", "info", "/nope", env=env), ros2("service", "info", "/nope", env=env)
    assert missing.returncode == expected.returncode == 1
    assert expected.stderr.strip() in missing.stderr and missing.stdout == ""


def test_service_info_verbose_lists_each_client_and_server_endpoint(graph):
    env = graph
    text = roc("service", "info", "-v", "/motor/enable", env=env).stdout
    clients, servers = text.split("Services count: 1\n")
    assert clients.startswith("Type: std_srvs/srv/SetBool\nClients count: 1\n\nNode name: motor\n")
    for block in (clients, servers):
        assert "Topic type: std_srvs/srv/SetBool_Request\n" in block
        assert "Topic type: std_srvs/srv/SetBool_Response\n" in block
        assert block.count("QoS profile:\n  Reliability: RELIABLE\n") == 2
    # a client writes requests and reads replies; a server the other way round
    assert "SetBool_Request\nTopic type hash: RIHS01_" in clients
    data = json.loads(roc("service", "info", "-v", "/motor/enable", "--format", "json", env=env).stdout)
    assert (data["clients_count"], data["services_count"]) == (1, 1)
    kinds = {(e["topic_type"], e["endpoint_type"]) for e in data["clients"]}
    assert kinds == {("std_srvs/srv/SetBool_Request", "PUBLISHER"), ("std_srvs/srv/SetBool_Response", "SUBSCRIPTION")}
    kinds = {(e["topic_type"], e["endpoint_type"]) for e in data["servers"]}
    assert kinds == {("std_srvs/srv/SetBool_Request", "SUBSCRIPTION"), ("std_srvs/srv/SetBool_Response", "PUBLISHER")}


def test_hidden_services_are_unknown_without_the_option(graph):
    env = graph
    hidden = "/fibonacci/_action/send_goal"
    unknown = roc("service", "info", hidden, env=env)
    assert (unknown.returncode, unknown.stderr) == (1, f"roc: error: Unknown service '{hidden}'\n")
    assert roc("service", "info", "--include-hidden-services", hidden, env=env).stdout == \
        "Type: test_msgs/action/Fibonacci_SendGoal\nClients count: 0\nServices count: 1\n"


def _echo(command: list[str], env: dict[str, str]) -> subprocess.Popen:
    return subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _more(process: subprocess.Popen, seen: str) -> str:
    """``seen`` and whatever the process printed since, without waiting for more."""
    while (line := read_line(process, timeout=0.3)) is not None:
        assert line, f"the echo ended: {seen!r}, {process.stderr.read() if process.poll() is not None else ''}"
        seen += line
    return seen


def _answered(text: str, value: int) -> bool:
    """Whether a service echo has printed the response to the call with ``int32_value: value``."""
    return any("RESPONSE_SENT" in block and f"int32_value: {value}\n" in block.split("response:")[-1]
               for block in text.split("---\n"))


def call_until_echoed(env: dict[str, str], echoes: list[subprocess.Popen]) -> list[str]:
    """Call /echo_types again and again until every echo shows a response (each has subscribed then),
    and once more; what each printed, ending with the last call's two events (an echo that subscribed
    between a request and its response shows the response only, so that call's are not compared)."""
    texts = [""] * len(echoes)
    subscribed = None
    for value in range(1, 60):
        called = roc("service", "call", "/echo_types", "test_msgs/srv/BasicTypes", f"{{int32_value: {value}}}",
                     env=env)
        assert called.returncode == 0, called.stderr
        texts = [_more(process, text) for process, text in zip(echoes, texts)]
        deadline = time.monotonic() + (10 if subscribed else 0)
        while not all(_answered(text, value) for text in texts) and time.monotonic() < deadline:
            texts = [_more(process, text) for process, text in zip(echoes, texts)]
        if all(_answered(text, value) for text in texts):
            if subscribed is not None:
                return texts
            subscribed = value
        else:
            assert subscribed is None, f"the echoes missed a call: {texts}"
    raise AssertionError(f"the echoes never showed a response: {texts}")


def test_service_echo_prints_what_ros2_prints(graph):
    env = graph
    echoes = [_echo([str(BIN / "roc"), "service", "echo", "/echo_types"], env),
              _echo([str(ORACLE_VENV / "bin" / "ros2"), "service", "echo", "/echo_types"], env)]
    try:
        got, expected = (text.split("---\n")[-3:-1] for text in call_until_echoed(env, echoes))
        assert got == expected
        assert got[0].startswith("info:\n  event_type: REQUEST_RECEIVED\n  stamp:\n")
        assert "request:\n- bool_value: false\n" in got[0] and got[1].startswith("info:\n  event_type: RESPONSE_SENT")
    finally:
        for process in echoes:
            stop_process(process)


def test_service_echo_json_and_the_warning_without_introspection(graph):
    env = graph
    echo = _echo([str(BIN / "roc"), "service", "echo", "/echo_types", "--format", "json"], env)
    try:
        events = [json.loads(line) for line in call_until_json(env, echo).splitlines()]
        assert {e["service"] for e in events} == {"/echo_types"}
        assert [e["event"]["info"]["event_type"] for e in events[-2:]] == ["REQUEST_RECEIVED", "RESPONSE_SENT"]
        assert events[-1]["event"]["response"][0]["int32_value"] == events[-2]["event"]["request"][0]["int32_value"]
    finally:
        stop_process(echo)
    quiet = [_echo([str(BIN / "roc"), "service", "echo", "/motor/enable"], env),
             _echo([str(ORACLE_VENV / "bin" / "ros2"), "service", "echo", "/motor/enable"], env)]
    try:
        first = [read_line(process) for process in quiet]
        assert first[0] == first[1] == ("No publishers on topic '/motor/enable/_service_event'; is service "
                                        "introspection on the client or server enabled?\n")
    finally:
        for process in quiet:
            stop_process(process)


def call_until_json(env: dict[str, str], echo: subprocess.Popen) -> str:
    """Call /echo_types until a JSON echo shows a response, then once more (see call_until_echoed); its
    lines, ending with the last call's two events."""
    text, subscribed = "", False
    for value in range(1, 60):
        roc("service", "call", "/echo_types", "test_msgs/srv/BasicTypes", f"{{int32_value: {value}}}", env=env)
        deadline = time.monotonic() + (10 if subscribed else 0.3)
        while time.monotonic() < deadline:
            text = _more(echo, text)
            if '"RESPONSE_SENT"' in text and (not subscribed or f'"int32_value":{value},' in text.splitlines()[-1]):
                break
        if subscribed:
            return text
        subscribed = '"RESPONSE_SENT"' in text
    raise AssertionError("the JSON echo never showed a response")


def test_call_and_send_goal_read_their_values_from_stdin(graph):
    env = graph
    command = ("service", "call", "/echo_types", "test_msgs/srv/BasicTypes")
    given = roc(*command, "{int32_value: 3, string_value: piped}", env=env)
    piped = subprocess.run([str(BIN / "roc"), *command, "--stdin"], input="int32_value: 3\nstring_value: piped\n",
                           env=env, capture_output=True, text=True, timeout=60)
    assert piped.returncode == 0 and piped.stdout == given.stdout and "string_value='piped'" in piped.stdout
    goal = subprocess.run([str(BIN / "roc"), "action", "send_goal", "/fibonacci", "test_msgs/action/Fibonacci",
                           "--stdin"], input="order: 3\n", env=env, capture_output=True, text=True, timeout=60)
    assert goal.returncode == 0, goal.stderr
    assert "Sending goal:\n     order: 3\n" in goal.stdout and "Goal finished with status: SUCCEEDED" in goal.stdout
    both = roc(*command, "{}", "--stdin", env=env)
    assert both.returncode == 2 and "not allowed with argument" in both.stderr
    bad = subprocess.run([str(BIN / "roc"), *command, "--stdin"], input="int32_value: [\n", env=env,
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode != 0 and bad.stderr.startswith("roc: error: standard input: line ")


def _parameter_lines(text: str) -> list[str]:
    """A param listing without ros2's complaints about nodes that have no parameter services."""
    return [line for line in text.splitlines() if not line.startswith("Wait for service timed out")]


def test_param_list_include_hidden_nodes_as_ros2(graph):
    env = graph
    shown = roc("param", "list", "--include-hidden-nodes", env=env)
    assert "/_hidden:\n  secret\n" in shown.stdout and "/_hidden:" not in roc("param", "list", env=env).stdout
    expected = ros2("param", "list", "--include-hidden-nodes", env=env)
    assert _parameter_lines(shown.stdout) == _parameter_lines(expected.stdout)
    for command in (("param", "list", "/_hidden"), ("param", "list", "/_hidden", "--include-hidden-nodes")):
        got, oracle = roc(*command, env=env), ros2(*command, env=env)
        assert (got.returncode, got.stdout) == (oracle.returncode, oracle.stdout)
        assert oracle.stderr.strip() in got.stderr


def _built_demo_interfaces(workspace: Path, env: dict[str, str]) -> dict[str, str]:
    """demo_interfaces of the example workspace built by roc into ``workspace``: the environment of a shell
    that sourced it (a robot that has the package; roc's own environment does not)."""
    shutil.copytree(REPO / "workspaces" / "example" / "src" / "demo_interfaces", workspace / "src" / "demo_interfaces")
    # built on the wheels alone: with the oracle's venv first, CMake would take its python3, which need not
    # have ament_package
    built = subprocess.run([str(BIN / "roc"), "work", "build"], cwd=workspace, env={**env, "AMENT_PREFIX_PATH": sys.prefix},
                           capture_output=True, text=True, timeout=600)
    assert built.returncode == 0, built.stdout + built.stderr
    sourced = subprocess.run(["bash", "-c", "source install/setup.bash && env -0"], cwd=workspace, env=env,
                             capture_output=True, text=True, timeout=60)
    assert sourced.returncode == 0, sourced.stderr
    return dict(line.split("=", 1) for line in sourced.stdout.split("\0") if "=" in line)


def test_interface_show_asks_a_node_for_a_type_not_installed_here(graph, tmp_path: Path):
    """A node on the graph publishes demo_interfaces/msg/Reading, which only its own environment has: roc,
    unsourced, shows the type from the node's type description service, as ros2 shows it where the
    package is installed."""
    env = graph
    robot = _built_demo_interfaces(tmp_path / "robot", env)
    node = start_nodes([{"name": "reader", "publishers": [{"topic": "readings", "type": "demo_interfaces/msg/Reading"}]}],
                       robot)
    try:
        wait_for(lambda: "/reader" in roc("node", "list", env=env).stdout)
        for flags in ((), ("--no-comments",), ("--all-comments",)):
            shown = roc("interface", "show", "demo_interfaces/msg/Reading", *flags, env=env)
            assert shown.returncode == 0, shown.stderr
            assert shown.stdout == ros2("interface", "show", "demo_interfaces/msg/Reading", *flags, env=robot).stdout
        data = json.loads(roc("interface", "show", "demo_interfaces/msg/Reading", "--format", "json", env=env).stdout)
        assert (data["node"], data["file"]) == ("/reader", None)
        no_daemon = roc("interface", "show", "demo_interfaces/msg/Reading", "--no-daemon", env=env)
        assert no_daemon.stdout == ros2("interface", "show", "demo_interfaces/msg/Reading", env=robot).stdout
        unknown = roc("interface", "show", "nowhere_msgs/msg/Thing", env=env)
        assert unknown.returncode == 1 and "Unknown package 'nowhere_msgs'" in unknown.stderr
    finally:
        stop_all(node)
