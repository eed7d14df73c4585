"""Fast checks of the ported ros2cli cases' harness (tests/helpers/ros2cli.py): launch_testing's line
matching and output filters, on which every ported case's verdict rests."""

from __future__ import annotations

import re

from helpers.ros2cli import expect_lines, output_filter

OUTPUT = "roc: error: Unknown topic '/x'\nType: std_msgs/msg/String\n\nPublisher count: 1\n"


def test_a_string_expects_a_line_that_contains_it_and_a_pattern_one_it_matches_from_its_start() -> None:
    assert expect_lines(OUTPUT, ["Unknown topic '/x'"], strict=True)  # a part of the first line
    assert expect_lines(OUTPUT, [re.compile(r"Type: \w+")])
    assert not expect_lines(OUTPUT, [re.compile(r"Unknown topic")])  # not from the line's start
    assert expect_lines(OUTPUT, [""] * 4, strict=True) and not expect_lines(OUTPUT, [""] * 5)


def test_strict_expects_the_lines_in_a_row_from_the_first_and_lets_more_follow() -> None:
    assert expect_lines(OUTPUT, ["roc: error", "Type:", "", "Publisher count: 1"], strict=True)
    assert expect_lines(OUTPUT, ["roc: error", "Type:"], strict=True)  # more lines may follow
    assert not expect_lines(OUTPUT, ["Type:", "Publisher count: 1"], strict=True)  # not from the first
    assert not expect_lines(OUTPUT, ["roc: error", "Publisher count: 1"], strict=True)  # a line between
    assert expect_lines(OUTPUT, ["Type:", "Publisher count: 1"])  # in order, anywhere
    assert not expect_lines(OUTPUT, ["Publisher count: 1", "Type:"])  # but in order


def test_filters_drop_the_lines_that_start_with_a_prefix_or_match_a_pattern() -> None:
    text = "WARNING: topic [/a] does not appear to be published yet\nwaiting for service\n/_ros2cli_daemon_1\nkept\n"
    drop = output_filter(prefixes=["waiting for service"], patterns=["WARNING: topic .* does not appear",
                                                                      ".*ros2cli.*"])
    assert drop(text) == "kept\n"
