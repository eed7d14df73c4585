"""Test result files under a base directory, read as ``colcon test-result`` reads them.

Two kinds of files count: JUnit/xUnit XML (any ``*.xml`` whose root is ``testsuite`` or ``testsuites``,
in directories not starting with a dot) and CTest results (``Testing/TAG`` naming the latest
``Testing/<tag>/Test.xml``). Files that are neither are skipped, as colcon skips them.

Beyond colcon, each result says which of its tests never started and why (``not_started``): a test
file pytest could not import, or that skipped itself while being imported, or a run that wrote no
result file at all. colcon shows those only as "collection failure" (with --verbose).
"""

from __future__ import annotations

import ast
import copy
import os
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from roc.messages import warn
from roc.render import plural

COUNTS = ("tests", "errors", "failures", "skipped")
# colcon's attribute -> count mapping; None marks a required attribute.
SUITE_ATTRIBUTES = (("tests", "tests", None), ("errors", "errors", 0), ("failures", "failures", None),
                    ("skipped", "skip", 0), ("skipped", "skipped", 0), ("skipped", "disabled", 0))
# pytest's messages for a test file it could not import, or that skipped itself while being imported;
# the test case roc and colcon write before pytest runs, which stays when pytest writes no result file
COLLECTION_FAILURE, COLLECTION_SKIPPED = "collection failure", "collection skipped"
MISSING_RESULT_CASE = "pytest.missing_result"


class NotAResultFile(ValueError):
    """An XML file that is not a test result (skipped quietly)."""


@dataclass
class Result:
    """The counts of one result file (or of a summary of several)."""

    path: str
    tests: int = 0
    errors: int = 0
    failures: int = 0
    skipped: int = 0
    details: list[str] = field(default_factory=list)
    not_started: list[str] = field(default_factory=list)  # why tests never started, one line each
    # The file's test suites as JUnit elements, for merging into one report.
    suites: list = field(default_factory=list, repr=False)

    def add(self, other: Result) -> None:
        for name in COUNTS:
            setattr(self, name, getattr(self, name) + getattr(other, name))
        self.details += other.details
        self.not_started += other.not_started

    @property
    def ok(self) -> bool:
        return not (self.errors or self.failures)

    def line(self) -> str:
        """colcon's line: ``<path>: 3 tests, 0 errors, 1 failure, 1 skipped``."""
        return (f"{self.path}: {plural(self.tests, 'test')}, {plural(self.errors, 'error')}, "
                f"{plural(self.failures, 'failure')}, {self.skipped} skipped")

    def as_dict(self) -> dict:
        return {"path": self.path, **{name: getattr(self, name) for name in COUNTS}, "details": self.details,
                "not_started": self.not_started}


def _messages(label: str, messages: list[str]) -> list[str]:
    if not messages:
        return []
    lines = ["<<< " + label]
    for message in messages:
        lines += ["  " + line for line in (message or "").strip("\n\r").splitlines()]
    return lines + [">>>"]


def _testcase_details(case) -> str | None:
    """colcon's text for a test case with errors or failures, else None."""
    errors: list[str] = []
    failures: list[str] = []
    outs: list[str] = []
    errs: list[str] = []
    for child in case:
        target = {"error": errors, "failure": failures}.get(child.tag)
        if target is not None:
            target.append(child.get("message", ""))
        elif child.tag == "system-out":
            outs.append(child.text or "")
        elif child.tag == "system-err":
            errs.append(child.text or "")
    if not errors and not failures:
        return None
    label = [part for part in (case.get("classname"), case.get("name")) if part]
    if case.get("file"):
        line = case.get("line")
        label.append(f"({case.get('file')}{':' + line if line else ''})")
    return "\n".join([" ".join(label), *_messages("error message", errors), *_messages("failure message", failures),
                      *_messages("stdout output", outs), *_messages("stderr output", errs)])


def _test_file(case) -> str:
    """The test file of pytest's test case for a whole file (``test.test_copyright``: test/test_copyright.py)."""
    return case.get("name", "").replace(".", "/") + ".py"


def _last_error_line(text: str | None) -> str:
    """The exception of pytest's report of an error: its last ``E   `` line (else its last line)."""
    lines = [line for line in (text or "").splitlines() if line.strip()]
    errors = [line[1:].strip() for line in lines if line.startswith("E ")]
    return (errors or lines or ["(no details)"])[-1].strip()


def _skip_reason(text: str | None) -> str:
    """The reason of pytest's ``collection skipped`` case, whose text is ``(file, line, "Skipped: why")``."""
    try:
        reason = str(ast.literal_eval(text or "")[2])
    except (ValueError, SyntaxError, TypeError, IndexError):
        reason = (text or "").strip()
    return reason.removeprefix("Skipped: ")


def _not_started(case) -> str | None:
    """Why the tests of a test case never started, or None: ``error collecting FILE: EXCEPTION``,
    ``skipped collecting FILE: REASON``, or the message of a run that wrote no result file."""
    for child in case:
        message = child.get("message", "")
        if child.tag == "error" and message == COLLECTION_FAILURE:
            return f"error collecting {_test_file(case)}: {_last_error_line(child.text)}"
        if child.tag == "skipped" and message == COLLECTION_SKIPPED:
            return f"skipped collecting {_test_file(case)}: {_skip_reason(child.text)}"
        if child.tag == "failure" and case.get("name") == MISSING_RESULT_CASE:
            return message
    return None


def _suite_result(suite, details: bool) -> Result:
    result = Result("")
    for name, attribute, default in SUITE_ATTRIBUTES:
        text = suite.get(attribute)
        if text is None:
            if default is None:
                raise NotAResultFile(f"the '{attribute}' attribute is required")
            continue
        try:
            value = int(text)
        except ValueError:
            raise NotAResultFile(f"the '{attribute}' attribute should be an integer") from None
        if value < 0:
            raise NotAResultFile(f"the '{attribute}' attribute should be a positive integer")
        setattr(result, name, getattr(result, name) + value)
    cases = [case for case in suite if case.tag == "testcase"]
    result.not_started = [reason for case in cases for reason in [_not_started(case)] if reason]
    if details:
        result.details = [text for case in cases for text in [_testcase_details(case)] if text]
    result.suites = [suite]
    return result


def parse_junit(path: str, details: bool = False) -> Result:
    """One JUnit/xUnit file; raises NotAResultFile for other XML, etree.XMLSyntaxError if malformed."""
    root = etree.parse(path).getroot()
    if root.tag == "testsuites":
        suites = [child for child in root if child.tag == "testsuite"]
    elif root.tag == "testsuite":
        suites = [root]
    else:
        raise NotAResultFile("the root tag is neither 'testsuite' nor 'testsuites'")
    result = Result(path)
    for suite in suites:
        part = _suite_result(suite, details)
        result.add(part)
        result.suites += part.suites
    return result


def not_started(path: Path) -> list[str]:
    """Why the tests of a result file never started (empty when they all did, or the file is unreadable)."""
    try:
        return parse_junit(str(path)).not_started
    except (NotAResultFile, etree.XMLSyntaxError, OSError):
        return []


def _junit_results(base: Path, details: bool, files: set[str] | None) -> list[Result]:
    results = []
    for directory, dirnames, filenames in os.walk(str(base)):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        for filename in sorted(filenames):
            if not filename.endswith(".xml"):
                continue
            path = os.path.join(directory, filename)
            try:
                result = parse_junit(path, details)
            except NotAResultFile:
                continue
            except (etree.XMLSyntaxError, OSError) as error:
                warn(f"skipping '{path}': {error}")
                continue
            results.append(result)
            if files is not None:
                files.add(path)
    return results


def _ctest_case(test, status: str):
    """A CTest ``Test`` element as a JUnit ``testcase`` (for the merged report)."""
    case = etree.Element("testcase", name=test.findtext("Name") or "", classname=test.findtext("Path") or "")
    for measurement in test.iterfind("Results/NamedMeasurement"):
        if measurement.get("name") == "Execution Time":
            case.set("time", (measurement.findtext("Value") or "0").strip())
    output = test.findtext("Results/Measurement/Value") or ""
    if status == "failed":
        etree.SubElement(case, "failure", message="failed").text = output
    elif status == "notrun":
        etree.SubElement(case, "skipped")
    elif status != "passed":
        etree.SubElement(case, "error", message=status).text = output
    etree.SubElement(case, "system-out").text = output
    return case


def parse_ctest(tag_file: Path, details: bool, files: set[str] | None) -> Result | None:
    """The latest CTest run named by ``Testing/TAG``, or None when there is none to read."""
    if files is not None:
        files.add(str(tag_file))
    lines = tag_file.read_text().splitlines()
    xml_path = tag_file.parent / (lines[0] if lines else "") / "Test.xml"
    if not lines or not xml_path.is_file():
        warn(f"skipping '{tag_file}': could not find the latest XML file '{xml_path}'")
        return None
    try:
        root = etree.parse(str(xml_path)).getroot()
    except etree.XMLSyntaxError as error:
        warn(f"skipping '{xml_path}': {error}")
        return None
    children = list(root)
    if root.tag != "Site" or len(children) != 1 or children[0].tag != "Testing":
        warn(f"skipping '{xml_path}': not a CTest result ('Site' with one 'Testing' child)")
        return None
    if files is not None:
        files.add(str(xml_path))
    result = Result(str(xml_path))
    suite = etree.Element("testsuite", name="ctest")
    for test in children[0]:
        if test.tag != "Test":
            continue
        status = test.get("Status")
        if status is None:
            warn(f"skipping '{xml_path}': a 'Test' tag lacks a 'Status' attribute")
            return None
        result.tests += 1
        if status == "failed":
            result.failures += 1
            if details:
                output = test.findtext("Results/Measurement/Value")
                result.details.append("\n".join([test.findtext("Name") or "",
                                                  *_messages("failure message", [output] if output else [])]))
        elif status == "notrun":
            result.skipped += 1
        elif status != "passed":
            result.errors += 1
        suite.append(_ctest_case(test, status))
    for name in COUNTS:
        suite.set(name, str(getattr(result, name)))
    result.suites = [suite]
    return result


def collect_results(base: Path, details: bool = False, files: set[str] | None = None) -> list[Result]:
    """Every result file under ``base``, sorted by path; ``files`` collects every file read (for --delete)."""
    base = Path(base)
    results = _junit_results(base, details, files)
    for tag_file in sorted(base.glob("**/Testing/TAG")):
        if tag_file.is_file():
            result = parse_ctest(tag_file, details, files)
            if result is not None:
                results.append(result)
    return sorted(results, key=lambda result: result.path)


def summarize(results: list[Result]) -> Result:
    summary = Result("Summary")
    for result in results:
        summary.add(result)
    return summary


def package_of(path: str, base: Path) -> str:
    """The package a result file belongs to: the first directory below the base."""
    relative = os.path.relpath(path, base)
    return relative.split(os.sep, 1)[0]


def merged_junit(results: list[Result], base: Path) -> bytes:
    """Every result as one JUnit report: a ``testsuite`` per suite, named ``<package>.<suite>``."""
    summary = summarize(results)
    root = etree.Element("testsuites", {"name": "roc", **{name: str(getattr(summary, name)) for name in COUNTS}})
    for result in results:
        package = package_of(result.path, base)
        for suite in result.suites:
            suite = copy.deepcopy(suite)
            name = suite.get("name") or Path(result.path).stem
            suite.set("name", name if name.startswith(package + ".") else f"{package}.{name}")
            suite.set("file", result.path)
            root.append(suite)
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
