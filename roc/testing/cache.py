"""Cached test results: a package whose build, sources and test options are unchanged since a run in
which all its tests passed is not tested again. Kept in ``<build-base>/<pkg>/roc_test_state.json``."""

from __future__ import annotations

import json
from pathlib import Path

from roc.builder.fingerprint import changes, combine, source_parts, source_stamps
from roc.builder.state import read_record, read_state
from roc.fsutil import write_text_atomic

TEST_STATE_FILE = "roc_test_state.json"


def read_test_state(build_dir: Path) -> dict:
    return read_record(build_dir / TEST_STATE_FILE, "damaged test state; the package will be tested again")


def results_parts(source: Path, build_base: Path, name: str, dependencies: list[str], options: dict,
                  previous: dict) -> tuple[dict | None, dict]:
    """What a test run's outcome depends on (the package's build, its sources, the test options and its
    dependencies' builds) and the new file stamps; None when the build is not roc's (no fingerprint of
    what is built, so nothing to vouch for a cached result)."""
    fingerprint = read_state(build_base / name).get("fingerprint")
    files = source_stamps(source, previous.get("files", {}))
    if not fingerprint:
        return None, files
    return {"build": fingerprint, "sources": source_parts(files), "options": options,
            "dependencies": {n: read_state(build_base / n).get("fingerprint") for n in dependencies}}, files


def results_key(source: Path, build_base: Path, name: str, dependencies: list[str], options: dict,
                previous: dict) -> tuple[str | None, dict]:
    """The key of a test run (None when the build is not roc's) and the new file stamps."""
    parts, files = results_parts(source, build_base, name, dependencies, options, previous)
    return (combine(parts) if parts else None), files


def rerun_reasons(state: dict, parts: dict | None) -> list[str]:
    """Why a package's tests must run again; empty when the last run with the same key passed and its
    result files are still there (the result is cached)."""
    if parts is None:
        return ["not built by roc"]
    if not state:
        return ["never tested"]
    if state.get("passed") is not True:
        return ["failed last time"]
    if state.get("key") != combine(parts):
        before = state.get("parts")
        if not isinstance(before, dict):
            return ["test inputs changed"]
        reasons = ["build changed"] if before.get("build") != parts["build"] else []
        reasons += changes({**before, "sources": source_parts(state.get("files", {}))}, parts)
        return reasons or ["test inputs changed"]
    if not all(Path(path).exists() for path in state.get("results", [])):
        return ["result files missing"]
    return []


def write_test_state(build_dir: Path, key: str | None, passed: bool, files: dict, results: list[str],
                     parts: dict | None = None) -> None:
    """The last run's state; ``parts`` (without the sources, which ``files`` has) say why a later key
    differs."""
    state = {"key": key, "passed": passed, "files": files, "results": results}
    if parts:
        state["parts"] = {name: value for name, value in parts.items() if name != "sources"}
    write_text_atomic(build_dir / TEST_STATE_FILE, json.dumps(state, separators=(",", ":")))
