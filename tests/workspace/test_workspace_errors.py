"""Broken workspaces and bad arguments: exit code 1 (2 for usage errors), one ``roc: error:`` line on
stderr that names the file (and line) and says what to do, and no traceback unless ``--debug``."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers.build import add_plain_package, copy_fixture, roc
from helpers.fixture_workspaces import run_roc

# fixture -> (file named in the message, what the message must also say)
BAD_FIXTURES = {
    "bad_malformed_xml": (r"src/broken/package\.xml:8: ", r"malformed XML: .*tag mismatch.*; fix the XML syntax"),
    "bad_missing_name": (r"src/nameless/package\.xml:2: ", r"has no <name>; add <name>\.\.\.</name>"),
    "bad_colcon_pkg": (r"src/bad_json/colcon\.pkg:3: ", r"invalid JSON: .* at column 28; fix the syntax"),
    "bad_duplicate_names": (r"src/first/same_name and src/second/same_name",
                            r"duplicate package name 'same_name'.*rename one, or put a COLCON_IGNORE file"),
    "bad_cycle": (r"cyc_a \(src/cyc_a\), cyc_b \(src/cyc_b\), cyc_c \(src/cyc_c\)",
                  r"Remove one of these dependencies to break the cycle"),
}


def assert_one_error_line(stderr: str) -> str:
    lines = stderr.splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith("roc: error: ")
    assert "Traceback" not in stderr
    return lines[0]


@pytest.mark.parametrize("fixture", sorted(BAD_FIXTURES))
def test_bad_workspace_gives_one_clear_error(fixture: str, tmp_path: Path) -> None:
    workspace = copy_fixture(fixture, tmp_path / fixture)
    result = run_roc("work", "list", cwd=workspace)
    assert result.returncode == 1
    assert result.stdout == ""
    line = assert_one_error_line(result.stderr)
    where, what = BAD_FIXTURES[fixture]
    assert re.search(where, line), line
    assert re.search(what, line), line


def test_cycle_message_shows_the_chain(tmp_path: Path) -> None:
    workspace = copy_fixture("bad_cycle", tmp_path / "bad_cycle")
    result = run_roc("work", "graph", cwd=workspace)
    line = assert_one_error_line(result.stderr)
    # Each step names the categories of the dependency: cyc_a <depend> cyc_b <build_depend> cyc_c
    # <exec_depend> cyc_a. The package outside the cycle is not part of the message.
    assert "dependency cycle: cyc_a -[build,run]-> cyc_b -[build]-> cyc_c -[run]-> cyc_a;" in line
    assert "outside" not in line


@pytest.mark.parametrize("verb", ["info", "graph", "list"])
def test_duplicate_names_fail_in_every_verb(verb: str, tmp_path: Path) -> None:
    workspace = copy_fixture("bad_duplicate_names", tmp_path / "bad_duplicate_names")
    # even when the duplicate is not among the selected packages
    result = run_roc("work", verb, "--packages-select", "other", cwd=workspace)
    assert result.returncode == 1
    assert "duplicate package name 'same_name'" in assert_one_error_line(result.stderr)


def test_unknown_package_is_a_usage_error_with_a_hint(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "selection")
    close = run_roc("work", "list", "--packages-up-to", "lib_c", cwd=workspace)
    assert close.returncode == 2
    line = assert_one_error_line(close.stderr)
    assert "--packages-up-to: no package named 'lib_c' in the workspace; did you mean " in line
    assert line.endswith("? (see 'roc work list --help')") and "lib_a" in line and "lib_b" in line
    far = run_roc("work", "graph", "--packages-above", "zzz", cwd=workspace)
    assert far.returncode == 2
    assert "run 'roc work list -n' to see the package names" in assert_one_error_line(far.stderr)


@pytest.mark.parametrize("arguments, message", [
    (["--packages-above-depth", "x", "core"], "--packages-above-depth: the first value must be a depth"),
    (["--packages-select-regex", "("], "--packages-select-regex: invalid pattern '('"),
    (["--base-paths", "nowhere"], "--base-paths: 'nowhere' is not a directory"),
    (["--packages-start", "tool", "--packages-end", "core"], "comes before --packages-start 'tool'"),
    (["--no-such-option"], "unrecognized arguments: --no-such-option"),
])
def test_bad_arguments_exit_2(arguments: list[str], message: str, tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "selection")
    result = run_roc("work", "list", *arguments, cwd=workspace)
    assert result.returncode == 2
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in result.stderr


@pytest.mark.parametrize("words", [["--debug", "work", "list"], ["work", "list", "--debug"]])
def test_debug_before_or_after_the_command_shows_the_traceback(tmp_path: Path, words: list[str]) -> None:
    workspace = copy_fixture("bad_missing_name", tmp_path / "bad_missing_name")
    result = run_roc(*words, cwd=workspace)
    assert result.returncode != 0
    assert "Traceback (most recent call last)" in result.stderr
    assert "ManifestError" in result.stderr and "has no <name>" in result.stderr


def write_package(directory: Path, body: str, name: str = "pkg") -> None:
    directory.mkdir(parents=True)
    (directory / "package.xml").write_text(
        f'<package format="3"><name>{name}</name><version>1.0.0</version><description>d</description>'
        f'<maintainer email="m@example.com">M</maintainer><license>MIT</license>\n{body}\n'
        "<export><build_type>ament_cmake</build_type></export></package>\n"
    )


@pytest.mark.parametrize("body, message", [
    ('<depend condition="$ROS_VERSION === 2">x</depend>', r"package\.xml:2: invalid condition attribute"),
    ("<depend></depend>", r"package\.xml:2: <depend> is empty; it must name a package"),
    ("<run_depend>x</run_depend>", r"package\.xml:2: <run_depend> is not allowed in package format 3"),
])
def test_invalid_manifest_content(body: str, message: str, tmp_path: Path) -> None:
    write_package(tmp_path / "ws" / "src" / "pkg", body)
    result = run_roc("work", "info", cwd=tmp_path / "ws")
    assert result.returncode == 1
    assert re.search(message, assert_one_error_line(result.stderr))


def test_invalid_setup_py_names_file_and_line(tmp_path: Path) -> None:
    package = tmp_path / "ws" / "src" / "py"
    package.mkdir(parents=True)
    (package / "setup.py").write_text("from setuptools import setup\n\nsetup(name='py',\n")
    result = run_roc("work", "list", cwd=tmp_path / "ws")
    assert result.returncode == 1
    assert re.search(r"src/py/setup\.py:3: invalid Python", assert_one_error_line(result.stderr))


def test_info_without_packages_fails_as_in_colcon(tmp_path: Path) -> None:
    (tmp_path / "ws" / "src").mkdir(parents=True)
    result = run_roc("work", "info", cwd=tmp_path / "ws")
    assert result.returncode == 1
    assert assert_one_error_line(result.stderr) == (
        f"roc: error: no packages found in {tmp_path / 'ws'}; run roc in a workspace or pass --base-paths")
    assert run_roc("work", "list", cwd=tmp_path / "ws").returncode == 0  # list and graph print nothing, as colcon


def test_unusable_package_name_is_an_error(tmp_path):
    (tmp_path / "src" / "weird").mkdir(parents=True)
    (tmp_path / "src" / "weird" / "colcon.pkg").write_text(json.dumps({"name": "we$(touch PWNED)ird",
                                                                       "type": "cmake"}))
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 1 and "is not usable" in result.stderr
    assert not (tmp_path / "PWNED").exists() and not (tmp_path / "install").exists()


@pytest.mark.slow
def test_unsupported_build_type_is_skipped_with_a_warning(tmp_path):
    (tmp_path / "src" / "rusty").mkdir(parents=True)
    (tmp_path / "src" / "rusty" / "package.xml").write_text(
        '<package format="3"><name>rusty</name><version>1.0.0</version><description>d</description>'
        '<maintainer email="m@example.com">m</maintainer><license>MIT</license>'
        "<export><build_type>ament_cargo</build_type></export></package>")
    add_plain_package(tmp_path, "alpha")
    result = roc("work", "build", cwd=tmp_path)
    assert result.returncode == 0 and "'ros.ament_cargo'" in result.stderr and "skipped" in result.stderr
    assert "Finished <<< alpha" in result.stdout
