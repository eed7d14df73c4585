"""``--junit-xml FILE``: the probes of a ``roc graph check`` run as a JUnit XML report (one test case
per probe, ``failure`` or ``error`` with the probe's message), written atomically when the run ends."""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

from roc.engine.events import Event, ProbeResult, RunFinished, TaskFailed, TaskFinished
from roc.fsutil import write_text_atomic


class JUnitReport:
    def __init__(self, path: Path, suite: str):
        self.path, self.suite = path, suite
        self.results: dict[str, ProbeResult] = {}
        self.durations: dict[str, float] = {}

    def __call__(self, event: Event) -> None:
        if isinstance(event, ProbeResult):
            self.results[event.key] = event
        elif isinstance(event, (TaskFinished, TaskFailed)):
            self.durations[event.key] = event.duration
        elif isinstance(event, RunFinished):
            self.write()

    def write(self) -> None:
        results = list(self.results.values())
        suite = ElementTree.Element("testsuite", {
            "name": self.suite, "tests": str(len(results)),
            "failures": str(sum(r.status == "fail" for r in results)),
            "errors": str(sum(r.status == "error" for r in results)),
            "time": f"{sum(self.durations.values()):.3f}"})
        for result in results:
            kind, _, name = result.task.partition(" ")
            case = ElementTree.SubElement(suite, "testcase", {
                "classname": f"{self.suite}.{kind}", "name": name,
                "time": f"{self.durations.get(result.key, 0.0):.3f}"})
            if result.status in ("fail", "error"):
                element = ElementTree.SubElement(case, "failure" if result.status == "fail" else "error",
                                                 {"message": result.message})
                element.text = result.message
            else:
                ElementTree.SubElement(case, "system-out").text = result.message
        root = ElementTree.Element("testsuites")
        root.append(suite)
        ElementTree.indent(root)
        text = ElementTree.tostring(root, encoding="unicode", xml_declaration=True)
        write_text_atomic(self.path, text + "\n")
