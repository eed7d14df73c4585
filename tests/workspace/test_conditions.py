"""REP 149 condition expressions (``condition="$ROS_VERSION == 2"``)."""

from __future__ import annotations

import importlib.util

import pytest

from roc.workspace.conditions import (
    ConditionError,
    condition_environment,
    evaluate_condition,
)

VARIABLES = {"ROS_VERSION": "2", "ROS_DISTRO": "jazzy", "ROS_PYTHON_VERSION": "3", "SPACED": "a b", "EMPTY": ""}

CASES = [
    ("$ROS_VERSION == 2", True),
    ("$ROS_VERSION == 1", False),
    ("$ROS_VERSION != 1", True),
    ("$ROS_DISTRO >= humble", True),   # comparisons are between strings
    ("$ROS_DISTRO < iron", False),
    ("$ROS_DISTRO <= jazzy", True),
    ("$ROS_DISTRO > rolling", False),
    ("2 == $ROS_VERSION", True),       # the variable may come second
    ("$ROS_VERSION == 2 and $ROS_DISTRO == jazzy", True),
    ("$ROS_VERSION == 2 and $ROS_DISTRO == humble", False),
    ("$ROS_VERSION == 1 or $ROS_DISTRO == jazzy", True),
    ("$ROS_VERSION == 1 or $ROS_DISTRO == humble", False),
    # 'and' binds tighter than 'or'
    ("$ROS_VERSION == 2 or $ROS_VERSION == 1 and $ROS_DISTRO == humble", True),
    ("($ROS_VERSION == 2 or $ROS_VERSION == 1) and $ROS_DISTRO == humble", False),
    ("(($ROS_VERSION == 2))", True),
    ('$ROS_VERSION == "2"', True),
    ("$ROS_VERSION == '2'", True),
    ('$SPACED == "a b"', True),         # quoted values may hold spaces
    ("$UNSET == ''", True),             # an unset variable is the empty string
    ('$UNSET == ""', True),
    ("$UNSET != ''", False),
    ("$EMPTY == $UNSET", True),
    ("$ROS_VERSION==2", True),          # no spaces needed around operators
    ("$ROS_DISTRO == jazzy-1", False),  # values may hold dashes
]


@pytest.mark.parametrize("text, expected", CASES)
def test_evaluate(text: str, expected: bool) -> None:
    assert evaluate_condition(text, VARIABLES) is expected


needs_catkin_pkg = pytest.mark.skipif(importlib.util.find_spec("catkin_pkg") is None,
                                      reason="catkin_pkg (from colcon-ros) is not installed")
quiet_pyparsing = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # catkin_pkg's use of pyparsing


@pytest.mark.parametrize("text, expected", CASES)
@needs_catkin_pkg
@quiet_pyparsing
def test_same_result_as_catkin_pkg(text: str, expected: bool) -> None:
    """catkin_pkg evaluates conditions for colcon: the reference."""
    from catkin_pkg.condition import evaluate_condition as catkin_evaluate

    assert catkin_evaluate(text, VARIABLES) is expected


@pytest.mark.parametrize("text", [None, "", "   "])
def test_no_condition_holds(text: str | None) -> None:
    assert evaluate_condition(text, {}) is True


INVALID = [
    "$ROS_VERSION ==",
    "== 2",
    "$ROS_VERSION = 2",
    "$ROS_VERSION == 2 and",
    "($ROS_VERSION == 2",
    "$ROS_VERSION == 2)",
    "$ROS_VERSION 2",
    "and",
    "$ROS_VERSION == 2 $ROS_DISTRO == jazzy",
    '$ROS_VERSION == "2',
    "$ == 2",
]


@pytest.mark.parametrize("text", INVALID)
def test_invalid_syntax(text: str) -> None:
    with pytest.raises(ConditionError, match="condition"):
        evaluate_condition(text, VARIABLES)


@pytest.mark.parametrize("text", INVALID)
@needs_catkin_pkg
@quiet_pyparsing
def test_catkin_pkg_rejects_them_too(text: str) -> None:
    from catkin_pkg.condition import evaluate_condition as catkin_evaluate

    with pytest.raises(ValueError):
        catkin_evaluate(text, VARIABLES)


def test_error_message_quotes_the_condition() -> None:
    with pytest.raises(ConditionError) as error:
        evaluate_condition("$ROS_VERSION == 2 and", VARIABLES)
    assert "'$ROS_VERSION == 2 and'" in str(error.value)


def test_environment_defaults_to_ros_2_and_python_3() -> None:
    assert condition_environment({}) == {"ROS_VERSION": "2", "ROS_PYTHON_VERSION": "3"}
    variables = condition_environment({"ROS_VERSION": "1", "ROS_DISTRO": "noetic"})
    assert variables["ROS_VERSION"] == "1" and variables["ROS_DISTRO"] == "noetic"
    assert variables["ROS_PYTHON_VERSION"] == "3"
