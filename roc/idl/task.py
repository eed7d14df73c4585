"""The ``idl`` task of ``roc work build``: code generation for a package with protobuf sources.

A package whose package.xml exports ``<roc_idl>DIR</roc_idl>`` gets, besides its ``build`` task, a task
of kind ``idl`` that the build task waits for. It runs ``python -m roc.idl.codegen`` (a command of its
own, so its output is in the task's log, ``log/<run>/<pkg>/idl/``, and Ctrl+C stops it), which writes the
.msg files, ``roc_idl.cmake`` and protoc's Python modules into ``<build-base>/<pkg>/roc_idl``, rewriting
only the files whose text changed. The build passes that directory to CMake (``-DROC_IDL_DIR``), and the
package's fingerprint counts the files in it (roc.builder.uptodate).

The task is up to date when the .proto files, the code generator and the generated files are what its
last successful run recorded in ``<build-base>/<pkg>/roc_idl_state.json``.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import sys
from pathlib import Path

MARKER = "roc_idl"
OUTPUT = "roc_idl"  # the output directory, in the package's build directory
STATE_FILE = "roc_idl_state.json"


def proto_directory(source: Path) -> Path | None:
    """The package's protobuf source directory, when its package.xml exports ``<roc_idl>DIR</roc_idl>``."""
    manifest = source / "package.xml"
    try:
        if MARKER.encode() not in manifest.read_bytes():  # most packages: no XML parse
            return None
    except OSError:
        return None
    from lxml import etree

    element = etree.parse(str(manifest)).find(f"export/{MARKER}")
    return source / (element.text or "proto").strip() if element is not None else None


def generated_directory(source: Path, build_dir: Path) -> Path | None:
    """Where the package's generated files are, when it has protobuf sources."""
    return build_dir / OUTPUT if proto_directory(source) is not None else None


def cmake_arguments(build_dir: Path) -> list[str]:
    """What the package's CMake configure needs to find the generated files."""
    return [f"-DROC_IDL_DIR={build_dir / OUTPUT}"]


@functools.cache
def generator_stamp() -> str:
    """The code generator's identity: roc's IDL modules (a new roc generates anew)."""
    digest = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def read_state(build_dir: Path) -> dict:
    """The last successful generation's record; {} when there is none or it is damaged."""
    try:
        state = json.loads((build_dir / STATE_FILE).read_text())
    except (OSError, ValueError):
        return {}
    valid = isinstance(state, dict) and all(isinstance(state.get(k), dict) for k in ("inputs", "outputs"))
    return state if valid else {}


def stale_reasons(source: Path, build_dir: Path, forced: list[str] = ()) -> list[str]:
    """Why the generated files must be made again (empty: up to date)."""
    if forced:
        return list(forced)
    stored = read_state(build_dir)
    if not stored:
        return ["never generated"]
    from roc.builder.fingerprint import changes, source_parts

    before = {"sources": source_parts(stored["inputs"]), "generated": source_parts(stored["outputs"])}
    now = {"sources": source_parts(_inputs(source, stored["inputs"])),
           "generated": source_parts(_outputs(build_dir, stored["outputs"]))}
    reasons = [reason.replace("generated files removed", "generated files missing") for reason in changes(before, now)]
    if stored.get("generator") != generator_stamp():
        reasons.append("code generator changed")
    return reasons


def _inputs(source: Path, previous: dict) -> dict:
    """The stamps of the package's .proto files, by path relative to the package."""
    from roc.builder.fingerprint import source_stamps

    directory = proto_directory(source)
    if directory is None or not directory.is_dir():
        return {}
    prefix = os.path.relpath(directory, source)
    old = {os.path.relpath(path, prefix): stamp for path, stamp in previous.items()}
    return {os.path.normpath(os.path.join(prefix, path)): stamp
            for path, stamp in source_stamps(directory, old).items() if path.endswith(".proto")}


def _outputs(build_dir: Path, previous: dict) -> dict:
    from roc.builder.fingerprint import source_stamps

    out = build_dir / OUTPUT
    return source_stamps(out, previous) if out.is_dir() else {}


class IdlGeneration:
    """The check and the action of one package's ``idl`` task."""

    def __init__(self, name: str, source: Path, build_dir: Path, forced: list[str], record: bool):
        self.name, self.source, self.build_dir = name, source, build_dir
        self.forced = forced  # options that generate whatever the state (--force, --no-cache)
        self.record = record  # keep a state for the next run (not with --no-cache)

    def check(self) -> list[str]:
        return stale_reasons(self.source, self.build_dir, self.forced)

    def command(self) -> list[str]:
        return [sys.executable, "-m", "roc.idl.codegen", self.name, str(proto_directory(self.source)),
                str(self.build_dir / OUTPUT)]

    def run(self, context) -> None:
        from roc.builder.environment import base_environment
        from roc.engine.process import TaskError
        from roc.fsutil import write_text_atomic

        state = self.build_dir / STATE_FILE
        # Stamped before generating, so that an edit made during the run shows next time.
        inputs = _inputs(self.source, read_state(self.build_dir).get("inputs", {}))
        self.build_dir.mkdir(parents=True, exist_ok=True)
        state.unlink(missing_ok=True)  # until it succeeds, no old record may vouch for the outputs
        env = base_environment()
        roc_root = str(Path(__file__).resolve().parents[2])  # the codegen of this very roc
        env["PYTHONPATH"] = os.pathsep.join(p for p in (roc_root, env.get("PYTHONPATH")) if p)
        if context.run(self.command(), cwd=str(self.source), env=env) != 0:
            raise TaskError("code generation failed")
        if self.record:
            record = {"generator": generator_stamp(), "inputs": inputs, "outputs": _outputs(self.build_dir, {})}
            write_text_atomic(state, json.dumps(record, separators=(",", ":")))
