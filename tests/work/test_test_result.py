"""``roc work test-result`` against ``colcon test-result`` on hand-written result files."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.build import colcon, roc
from lxml import etree

GTEST = """<?xml version="1.0" encoding="UTF-8"?>
<testsuites tests="3" failures="1" disabled="1" errors="0" name="AllTests">
  <testsuite name="Math" tests="3" failures="1" disabled="1" skipped="0" errors="0">
    <testcase name="Adds" file="test.cpp" line="3" classname="Math"/>
    <testcase name="Fails" file="test.cpp" line="4" classname="Math">
      <failure message="Expected equality&#x0A;  2 vs 3">details</failure>
    </testcase>
    <testcase name="DISABLED_Later" status="notrun" classname="Math"/>
  </testsuite>
</testsuites>
"""
PYTEST = """<?xml version="1.0" encoding="utf-8"?><testsuites name="pytest tests"><testsuite name="pytest"
 errors="1" failures="0" skipped="1" tests="3"><testcase classname="pkg.test" name="test_ok"/>
 <testcase classname="pkg.test" name="test_error"><error message="setup failed">trace</error>
 <system-out>printed</system-out></testcase><testcase classname="pkg.test" name="test_skip">
 <skipped message="later"/></testcase></testsuite></testsuites>
"""
PASSING = '<testsuite name="p" tests="1" failures="0"><testcase name="one" classname="c"/></testsuite>'
CTEST = """<?xml version="1.0" encoding="UTF-8"?>
<Site BuildName="x" Name="y"><Testing>
  <Test Status="passed"><Name>first</Name><Path>.</Path></Test>
  <Test Status="failed"><Name>second</Name><Path>.</Path>
    <Results><Measurement><Value>it broke
on two lines</Value></Measurement></Results></Test>
  <Test Status="notrun"><Name>third</Name><Path>.</Path></Test>
</Testing></Site>
"""


@pytest.fixture
def results(tmp_path: Path) -> Path:
    files = {
        "build/a/test_results/a/math.gtest.xml": GTEST,
        "build/b/pytest.xml": PYTEST,
        "build/c/pytest.xml": PASSING,
        "build/d/Testing/20260101-0000/Test.xml": CTEST,
        "build/d/Testing/TAG": "20260101-0000\nExperimental\n",
        "build/e/not_a_result.xml": "<package><name>e</name></package>",
        "build/e/.hidden/pytest.xml": PASSING,
        "build/e/CMakeFiles/notes.txt": "no xml",
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    return tmp_path


@pytest.mark.slow  # runs the real colcon
@pytest.mark.parametrize("options", [(), ("--all",), ("--verbose",), ("--all", "--verbose"),
                                     ("--result-files-only",), ("--result-files-only", "--all")])
def test_output_equals_colcon(results: Path, options: tuple[str, ...]) -> None:
    expected = colcon("test-result", *options, cwd=results)
    actual = roc("work", "test-result", *options, cwd=results)
    assert (actual.stdout, actual.returncode) == (expected.stdout, expected.returncode)
    assert expected.returncode == 1


def test_summary_and_exit_code_when_all_pass(tmp_path: Path) -> None:
    (tmp_path / "build" / "c").mkdir(parents=True)
    (tmp_path / "build" / "c" / "pytest.xml").write_text(PASSING)
    result = roc("work", "test-result", cwd=tmp_path)
    assert (result.stdout, result.returncode) == ("Summary: 1 test, 0 errors, 0 failures, 0 skipped\n", 0)


def test_json_and_merged_junit(results: Path) -> None:
    import json

    result = roc("work", "test-result", "--format", "json", "--junit-xml", "out/all.xml", cwd=results)
    assert result.returncode == 1
    data = json.loads(result.stdout)
    assert data["summary"] == {"tests": 10, "errors": 1, "failures": 2, "skipped": 3}
    assert [r["path"] for r in data["results"]] == [
        "build/a/test_results/a/math.gtest.xml", "build/b/pytest.xml", "build/d/Testing/20260101-0000/Test.xml"]
    root = etree.parse(str(results / "out" / "all.xml")).getroot()
    assert root.tag == "testsuites"
    assert {k: root.get(k) for k in ("tests", "errors", "failures", "skipped")} == {
        "tests": "10", "errors": "1", "failures": "2", "skipped": "3"}
    assert [s.get("name") for s in root] == ["a.Math", "b.pytest", "c.p", "d.ctest"]
    assert [c.get("name") for c in root[3]] == ["first", "second", "third"]
    assert root[3][1].find("failure").text.startswith("it broke")


def test_delete(results: Path) -> None:
    refused = roc("work", "test-result", "--delete", cwd=results)
    assert refused.returncode == 2 and "--delete-yes" in refused.stderr
    assert (results / "build/b/pytest.xml").exists()
    deleted = roc("work", "test-result", "--delete-yes", cwd=results)
    assert deleted.returncode == 0 and deleted.stdout.endswith("Deleted 5 files\n")
    assert not (results / "build/d/Testing/TAG").exists()
    assert (results / "build/e/not_a_result.xml").exists() and (results / "build/e/.hidden/pytest.xml").exists()
    again = roc("work", "test-result", cwd=results)
    assert again.stdout == "Summary: 0 tests, 0 errors, 0 failures, 0 skipped\n"


def test_missing_base_is_a_usage_error(tmp_path: Path) -> None:
    result = roc("work", "test-result", "--test-result-base", "nowhere", cwd=tmp_path)
    assert result.returncode == 2 and "'nowhere' does not exist" in result.stderr


# pytest's result when it could not import one test file and another skipped itself while imported
NOT_STARTED = """<?xml version="1.0" encoding="utf-8"?><testsuites name="pytest tests"><testsuite name="pytest"
 errors="1" failures="0" skipped="1" tests="2"><testcase classname="p" name="test.test_copyright" time="0.000">
<error message="collection failure">ImportError while importing test module '/ws/src/p/test/test_copyright.py'.
Traceback:
test/test_copyright.py:1: in &lt;module&gt;
    from ament_copyright.main import main
E   ModuleNotFoundError: No module named 'ament_copyright'</error></testcase>
<testcase classname="" name="test.test_flake8" time="0.000"><skipped message="collection skipped">('/ws/src/p/test/test_flake8.py', 2, "Skipped: could not import 'ament_flake8': No module named 'ament_flake8'")</skipped></testcase>
</testsuite></testsuites>
"""


def test_tests_that_never_started_are_shown_with_why(tmp_path: Path) -> None:
    """colcon test-result shows only 'collection failure', and only with --verbose."""
    import json

    (tmp_path / "build" / "p").mkdir(parents=True)
    (tmp_path / "build" / "p" / "pytest.xml").write_text(NOT_STARTED)
    reasons = ["error collecting test/test_copyright.py: ModuleNotFoundError: No module named 'ament_copyright'",
               "skipped collecting test/test_flake8.py: could not import 'ament_flake8': No module named 'ament_flake8'"]
    result = roc("work", "test-result", cwd=tmp_path)
    assert result.returncode == 1
    assert result.stdout == ("build/p/pytest.xml: 2 tests, 1 error, 0 failures, 1 skipped\n"
                             + "".join(f"  {reason}\n" for reason in reasons)
                             + "\nSummary: 2 tests, 1 error, 0 failures, 1 skipped\n")
    assert json.loads(roc("work", "test-result", "--format", "json", cwd=tmp_path).stdout)["results"][0][
        "not_started"] == reasons
