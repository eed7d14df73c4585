"""roc topic echo / hz / bw --content-filter: DDS content filters (ros2/ros2cli#1126), evaluated by
the middleware (Fast DDS filters on the publisher's side: the bytes on the wire drop with the
messages), or by roc where the middleware does not; roc's evaluation agrees with Fast DDS's; a bad
filter is one line; a filtered subscription of the daemon is its client's alone."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys

import pytest
from helpers.build import BIN, NODES, stop_process
from helpers.graph import graph_env, read_line, roc, stop_daemon

from roc.ros.content_filter import ContentFilter, ContentFilterError

RATE = 50  # Hz of /numbers: "<n % 10> <n>", so that "data LIKE '3%'" passes one message in ten
MATCHING = ["--content-filter", "data LIKE %0", "--content-filter-params", "3%"]


# ---- the expressions, no graph ----------------------------------------------------------------------

def test_expressions_evaluate_as_dds_sql():
    from std_msgs.msg import String

    cases = {"data = 'a b'": ["a b"], "data <> 'a b'": ["ab", "b"], "data LIKE 'a%'": ["a b", "ab"],
             "data LIKE '_b'": ["ab"], "data MATCH 'a.*'": ["a b", "ab"], "NOT data > 'a'": [],
             "data BETWEEN 'a' AND 'ab' OR data = 'b'": ["a b", "ab", "b"]}
    for expression, accepted in cases.items():
        found = ContentFilter(expression)
        found.check(String)
        assert [text for text in ("a b", "ab", "b") if found.accepts(String(data=text))] == accepted, expression


def test_parameters_are_literals_and_a_bare_word_is_a_string():
    found = ContentFilter("a = %0 AND b = %1 AND c = %2 AND d = %3", ["hello", "'quoted'", "2.5", "TRUE"])
    assert found.parameters == ["'hello'", "'quoted'", "2.5", "TRUE"]


@pytest.mark.parametrize(("expression", "parameters", "error"), [
    ("data = ", [], 'expected a field, a value or a parameter at the end of "data = "'),
    ("data = 3", [], '= compares a string with a number, in "data = 3"'),
    ("nope = 'x'", [], "'nope': String has no field 'nope' (it has data)"),
    ("data = %1", ["x"], '"data = %1" uses %1 but 1 parameter(s) were given (--content-filter-params)'),
    ("data LIKE 3", [], 'LIKE compares strings, in "data LIKE 3"'),
    ("(data = 'x'", [], "expected ) at the end of \"(data = 'x'\""),
    ("'x' = 'y'", [], "each comparison needs a field, in \"'x' = 'y'\""),
    ("data = 'a b' data", [], "unexpected \"data\" (character 14) in \"data = 'a b' data\""),
    ("data IS 'x'", [], "expected a comparison (=, <>, <, <=, >, >=, LIKE, MATCH, BETWEEN) at \"IS\" (character 6) "
                        "in \"data IS 'x'\""),
    ('data = "x"', [], """cannot read '"x"' (character 8) in 'data = "x"'"""),
])
def test_a_bad_filter_says_what_is_wrong(expression, parameters, error):
    from std_msgs.msg import String

    with pytest.raises(ContentFilterError) as raised:
        ContentFilter(expression, parameters).check(String)
    assert str(raised.value) == f"--content-filter: {error}"


# ---- on a live graph ----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def numbers(tmp_path_factory):
    """/numbers at RATE Hz in a domain of its own; yields the environment."""
    env = graph_env(59, tmp_path_factory.mktemp("runtime"))
    publisher = subprocess.Popen([sys.executable, str(NODES / "content_filter_node.py"), str(RATE), "100"], env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert read_line(publisher, 30) == "ready\n"
        yield env
    finally:
        stop_process(publisher)
        stop_daemon(env)


def echo(env: dict[str, str], count: int, *options: str) -> tuple[list[int], str]:
    """The numbers of the first ``count`` messages roc topic echo prints, and its stderr."""
    process = subprocess.Popen([str(BIN / "roc"), "topic", "echo", "/numbers", "--format", "json", *options],
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        numbers = []
        while len(numbers) < count:
            line = read_line(process, 30)
            assert line, f"roc topic echo stopped: {process.stderr.read() if line == '' else 'no message'}"
            message = json.loads(line)
            assert message["lost"] == 0
            numbers.append(int(message["message"]["data"].split()[1]))
        process.send_signal(signal.SIGINT)
        return numbers, process.communicate(timeout=30)[1]
    finally:
        stop_process(process)


def every_tenth(numbers: list[int]) -> bool:
    """Only numbers ending in 3, and none of them missing between the first and the last."""
    return all(n % 10 == 3 for n in numbers) and numbers == list(range(numbers[0], numbers[-1] + 1, 10))


@pytest.mark.slow
def test_echo_receives_only_the_messages_that_pass(numbers):
    received, stderr = echo(numbers, 6, *MATCHING)
    assert every_tenth(received), received
    assert "roc: note" not in stderr  # the middleware filtered them


@pytest.mark.slow
def test_where_roc_filters_it_says_so_in_one_line_and_delivers_the_same(numbers):
    received, stderr = echo({**numbers, "ROC_MIDDLEWARE_CONTENT_FILTER": "0"}, 4, *MATCHING)
    assert every_tenth(received), received
    assert stderr.startswith("roc: note: asked to filter in roc (ROC_MIDDLEWARE_CONTENT_FILTER=0): roc filters "
                             "/numbers's messages as they arrive")
    assert stderr.count("\n") == 1 or "interrupted" in stderr.splitlines()[-1]


@pytest.mark.slow
def test_a_filtered_subscription_is_its_clients_alone(numbers):
    """An unfiltered echo on the same daemon at the same time still gets every message."""
    filtered = subprocess.Popen([str(BIN / "roc"), "topic", "echo", "/numbers", "--format", "json", *MATCHING],
                                env=numbers, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert read_line(filtered, 30)
        received, _ = echo(numbers, 25)
        assert received == list(range(received[0], received[0] + 25))
    finally:
        stop_process(filtered)


def reports(env: dict[str, str], verb: str, count: int, *options: str) -> list[dict]:
    """The first ``count`` JSON reports of roc topic hz or bw."""
    process = subprocess.Popen([str(BIN / "roc"), "topic", verb, "/numbers", "--format", "json", *options],
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        lines = [read_line(process, 30) for _ in range(count)]
        assert all(lines), lines
        return [json.loads(line) for line in lines]
    finally:
        stop_process(process)


@pytest.mark.slow
def test_hz_and_bw_measure_what_passes(numbers):
    assert reports(numbers, "hz", 3, "--window", "5", *MATCHING)[-1]["rate"] == pytest.approx(RATE / 10, rel=0.2)
    assert reports(numbers, "bw", 3, *MATCHING)[-1]["bytes_per_second"] == pytest.approx(RATE / 10 * 112, rel=0.2)


@pytest.mark.slow
def test_a_field_the_type_lacks_is_a_usage_error_as_a_syntax_error_is(numbers):
    """The field is checked in the daemon (it knows the topic's type), the syntax before asking it: one
    exit code and one form of line for both."""
    help_pointer = " (see 'roc topic echo --help')\n"
    result = roc("topic", "echo", "/numbers", "--content-filter", "number > 3", env=numbers)
    assert (result.returncode, result.stdout) == (2, "")
    assert result.stderr == ("roc: error: --content-filter: 'number': String has no field 'number' (it has data)"
                             + help_pointer)
    result = roc("topic", "echo", "/numbers", "--content-filter", "data >", env=numbers)
    assert (result.returncode, result.stdout) == (2, "")
    assert result.stderr == ('roc: error: --content-filter: expected a field, a value or a parameter at the end '
                             'of "data >"' + help_pointer)


@pytest.mark.slow
def test_roc_evaluates_filters_as_fast_dds_does(numbers):
    """The same expressions on the same messages: what Fast DDS delivers, what roc's own filter accepts."""
    result = subprocess.run([sys.executable, str(NODES / "content_filter_oracle.py")], env=numbers,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    verdicts = [json.loads(line) for line in result.stdout.splitlines()]
    assert len(verdicts) == 14 and any(v["fast_dds"] for v in verdicts)
    assert [v["roc"] for v in verdicts] == [v["fast_dds"] for v in verdicts]


@pytest.mark.slow
def test_the_publisher_sends_only_what_passes(numbers, tmp_path):
    """Bytes on the loopback interface of a network namespace of its own, Fast DDS on UDP only: the
    middleware's filter cuts them to about a tenth; roc's own filter (the same messages delivered)
    does not."""
    if os.geteuid() != 0 or not shutil.which("unshare") or subprocess.run(
            ["unshare", "-n", "true"], capture_output=True).returncode != 0:
        pytest.skip("a network namespace of its own needs root")
    env = {**numbers, "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}  # (only its loopback is there)
    result = subprocess.run(["unshare", "-n", sys.executable, str(NODES / "content_filter_wire.py"), "100", "2000", "2",
                             str(BIN / "roc")], env=env, capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, result.stderr
    runs = json.loads(result.stdout)
    print({name: (round(run["wire_bytes_per_message"]), run["published"], round(run["bw"]["bytes_per_second"]))
           for name, run in runs.items()})
    delivered = {name: run["bw"]["bytes_per_second"] for name, run in runs.items()}
    # what reaches roc topic bw: every message unfiltered, the tenth that passes with either filter
    # (ratios: a loaded machine publishes less than 100 Hz, each run at its own pace)
    assert delivered["middleware"] == pytest.approx(delivered["unfiltered"] / 10, rel=0.35)
    assert delivered["roc"] == pytest.approx(delivered["unfiltered"] / 10, rel=0.35)
    # what crosses the wire for each message published: the message and the protocol's own unfiltered; a
    # tenth of that with the middleware's filter; much more when roc filters (all of it on a quiet machine,
    # 2216, 283 and 2216 bytes; on a loaded one the bytes sent lag the messages published, down to 867
    # unfiltered: the bounds leave room for that; content_filter_bench.py measures the ratios)
    wire = {name: run["wire_bytes_per_message"] for name, run in runs.items()}
    assert all(run["published"] >= 20 for run in runs.values()), runs
    assert wire["unfiltered"] < 1.5 * 2000
    assert wire["middleware"] < 0.5 * wire["unfiltered"]
    assert wire["roc"] > 2 * wire["middleware"]
