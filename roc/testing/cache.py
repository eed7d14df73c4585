"""Cached test results: a package whose build, sources and test options are unchanged since a run in
which all its tests passed is not tested again. Kept in ``<build-base>/<pkg>/roc_test_state.json``."""

from __future__ import annotations

import json
from pathlib import Path

from roc.builder.fingerprint import combine, source_parts, source_stamps
from roc.builder.state import read_state
from roc.fsutil import write_text_atomic
from roc.messages import warn

TEST_STATE_FILE = "roc_test_state.json"


def read_test_state(build_dir: Path) -> dict:
    path = build_dir / TEST_STATE_FILE
    try:
        state = json.loads(path.read_text())
    except FileNotFoundError:
        return {}
    except (OSError, ValueError):
        warn(f"{path}: damaged test state; the package will be tested again")
        return {}
    return state if isinstance(state, dict) and isinstance(state.get("files", {}), dict) else {}


def results_key(source: Path, build_base: Path, name: str, dependencies: list[str], options: dict,
             previous: dict) -> tuple[str | None, dict]:
    """The key of a test run and the new file stamps; None when the build is not roc's (no fingerprint
    of what is built, so nothing to vouch for a cached result)."""
    fingerprint = read_state(build_base / name).get("fingerprint")
    files = source_stamps(source, previous.get("files", {}))
    sources = source_parts(files)
    if not fingerprint:
        return None, files
    key = combine({"build": fingerprint, "sources": sources, "options": options,
                   "dependencies": {n: read_state(build_base / n).get("fingerprint") for n in dependencies}})
    return key, files


def passed_before(state: dict, key: str | None) -> bool:
    """The last run with this key passed and its result files are still there."""
    return (key is not None and state.get("key") == key and state.get("passed") is True
            and all(Path(path).exists() for path in state.get("results", [])))


def write_test_state(build_dir: Path, key: str | None, passed: bool, files: dict, results: list[str]) -> None:
    state = {"key": key, "passed": passed, "files": files, "results": results}
    write_text_atomic(build_dir / TEST_STATE_FILE, json.dumps(state, separators=(",", ":")))
