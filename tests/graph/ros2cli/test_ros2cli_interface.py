"""ros2interface's CLI tests (ros2cli 0.32.2, test/test_cli.py), ported: each case runs against roc and
against the real ros2 (tests/helpers/ros2cli.py says how). No graph: interfaces come from the ament index.

ros2cli_test_interfaces (upstream's test package, not on PyPI) is stood in for by
tests/data/ros2cli_test_interfaces: an ament prefix with its ShortVaried* definitions, written from
what upstream's show cases expect them to print (``interface show`` reads the definition files only)."""

from __future__ import annotations

import itertools
import os
import re
import sys

import pytest
from helpers.build import DATA
from helpers.graph import ORACLE_VENV, graph_env, stop_daemon
from helpers.ros2cli import TOOLS, Cli, expect_lines, oracle, output_filter

pytestmark = pytest.mark.slow
__all__ = ["oracle"]

TEST_INTERFACES = DATA / "ros2cli_test_interfaces"
SOME_MESSAGES = ["test_msgs/msg/BasicTypes", "test_msgs/msg/Constants", "test_msgs/msg/Strings"]
SOME_SERVICES = ["test_msgs/srv/Arrays", "test_msgs/srv/BasicTypes", "test_msgs/srv/Empty"]
SOME_ACTIONS = ["test_msgs/action/Fibonacci"]
SOME_INTERFACES = SOME_MESSAGES + SOME_SERVICES + SOME_ACTIONS
INTERFACE_NAME = re.compile(r"\s*[A-z0-9_]+(/[A-z0-9_]+)+")
NESTED = "ros2cli_test_interfaces/{kind}/ShortVariedMultiNested"


@pytest.fixture(scope="module", params=TOOLS)
def cli(request, oracle, tmp_path_factory):  # noqa: F811
    # a domain and a daemon directory of its own: a verb that asks the graph starts a daemon, stopped here
    env = graph_env(40, tmp_path_factory.mktemp("runtime"), PYTHONUNBUFFERED="1",
                    AMENT_PREFIX_PATH=os.pathsep.join([str(TEST_INTERFACES), str(ORACLE_VENV), sys.prefix]))
    yield Cli(request.param, env)
    stop_daemon(env)


def test_list_interfaces(cli):
    result = cli.run("interface", "list", timeout=20)
    assert result.exit_code == 0
    lines = output_filter(prefixes=["Messages:", "Services:", "Actions:"])(result.output).splitlines()
    assert expect_lines("\n".join(lines), [INTERFACE_NAME] * len(lines), strict=True)
    assert expect_lines("\n".join(lines), SOME_INTERFACES)


@pytest.mark.parametrize("option, title, some", [("-m", "Messages:", SOME_MESSAGES), ("-s", "Services:", SOME_SERVICES),
                                                 ("-a", "Actions:", SOME_ACTIONS)],
                         ids=["messages", "services", "actions"])
def test_list_kind(cli, option, title, some):
    """upstream's test_list_messages, test_list_services and test_list_actions"""
    result = cli.run("interface", "list", option, timeout=20)
    assert result.exit_code == 0
    lines = result.output.splitlines()
    assert expect_lines(result.output, itertools.chain([title], [INTERFACE_NAME] * (len(lines) - 1)), strict=True)
    assert expect_lines(result.output, some)


def test_package_on_nonexistent_package(cli):
    result = cli.run("interface", "package", "not_a_package")
    assert result.exit_code == 1
    assert expect_lines(result.output, ["Unknown package 'not_a_package'"], strict=True), result.output


@pytest.mark.parametrize("options, kinds, some", [
    ((), "msg|srv|action", SOME_INTERFACES), (("-m",), "msg", SOME_MESSAGES), (("-s",), "srv", SOME_SERVICES),
    (("-a",), "action", SOME_ACTIONS)], ids=["all", "only_msgs", "only_srvs", "only_actions"])
def test_package_on_test_msgs(cli, options, kinds, some):
    """upstream's test_package_on_test_msgs and its _only_msgs, _only_srvs and _only_actions"""
    result = cli.run("interface", "package", "test_msgs", *options)
    assert result.exit_code == 0
    lines = result.output.splitlines()
    assert expect_lines(result.output, [re.compile(rf"test_msgs/({kinds})/[A-z0-9_]+")] * len(lines), strict=True)
    assert all(interface in lines for interface in some)


@pytest.mark.parametrize("option", [None, "-m", "-s", "-a"], ids=["all", "messages", "services", "actions"])
def test_packages(cli, option):
    """upstream's test_packages and test_packages_with_messages, _services and _actions"""
    result = cli.run("interface", "packages", *([option] if option else []))
    assert result.exit_code == 0
    assert "test_msgs" in result.output.splitlines()


SHOWN = {
    "": ["ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of {of}", "\tShortVaried short_varied",
         "\t\tbool BOOL_CONST=true", "\t\tbool bool_value", "\t\tbool[<=3] bool_values"],
    "--all-comments": [
        "ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of {of}", "\t# A short, varied type",
        "\tShortVaried short_varied # Comment - Nesting Level 2: 1 of 1", "\t\t# A constant",
        "\t\tbool BOOL_CONST=true # Comment - Nesting Level 1: 1 of 2", "", "\t\t# Bool and array of bools",
        "\t\tbool bool_value", "\t\tbool[<=3] bool_values # Comment - Nesting Level 1: 2 of 2", "",
        "\t\t# Trailing comment", "\t# Trailing comment"],
    "--no-comments": ["ShortVariedNested short_varied_nested", "\tShortVaried short_varied",
                      "\t\tbool BOOL_CONST=true", "\t\tbool bool_value", "\t\tbool[<=3] bool_values"],
}
SHOW_CASES = {  # kind: (lines before the nested field, lines after it, with comments; without comments)
    "msg": (["# A short, varied, and nested type"], ["# Trailing comment"], []),
    "srv": (["# Request"], ["---", "# Response", "bool bool_value # Comment - Nesting Level 3: 2 of 2"],
            ["---", "bool bool_value"]),
    "action": (["# Goal definition"],
               ["---", "# Result definition", "bool bool_value # Comment - Nesting Level 3: 2 of 2", "---",
                "# Feedback definition", "bool[3] bool_values"],
               ["---", "bool bool_value", "---", "bool[3] bool_values"]),
}


@pytest.mark.parametrize("option", SHOWN, ids=["default", "all_comments", "no_comments"])
@pytest.mark.parametrize("kind", SHOW_CASES, ids=["message", "service", "action"])
def test_show(cli, kind, option):
    """upstream's test_show_message, test_show_service and test_show_action, each also _with_all_comments
    and _with_no_comments"""
    before, after, after_without_comments = SHOW_CASES[kind]
    nested = [line.format(of=1 if kind == "msg" else 2) for line in SHOWN[option]]
    expected = nested + after_without_comments if option == "--no-comments" else before + nested + after
    result = cli.run("interface", "show", NESTED.format(kind=kind), *([option] if option else []))
    assert result.exit_code == 0
    assert expect_lines(result.output, expected, strict=True), result.output


def test_show_not_a_package(cli):
    result = cli.run("interface", "show", "not_a_package/msg/String")
    assert result.exit_code == 1
    assert expect_lines(result.output, ["Unknown package 'not_a_package'"], strict=True), result.output


def test_show_not_an_interface(cli):
    result = cli.run("interface", "show", "test_msgs/msg/NotAMessageTypeName")
    assert result.exit_code == 1
    assert expect_lines(result.output, [re.compile(r"Could not find the interface '.+NotAMessageTypeName\.idl'")],
                        strict=True), result.output


def test_show_stdin(cli):
    result = cli.shell(f"{sys.executable} -c 'print(\"test_msgs/msg/BasicTypes\")' | CLI interface show -")
    assert result.exit_code == 0
    assert expect_lines(result.output, [
        "bool bool_value", "byte byte_value", "char char_value", "float32 float32_value", "float64 float64_value",
        "int8 int8_value", "uint8 uint8_value", "int16 int16_value", "uint16 uint16_value", "int32 int32_value",
        "uint32 uint32_value", "int64 int64_value", "uint64 uint64_value"], strict=True), result.output
