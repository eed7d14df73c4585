"""The ``idl`` task of ``roc work build``: code generation for a package with protobuf sources.

A package whose package.xml exports ``<roc_idl>DIR</roc_idl>`` gets, besides its ``build`` task, a task
of kind ``idl`` (key ``idl:<pkg>``) that the build task waits for. It runs ``python -m roc.idl.codegen``
(a command of its own, so its output is in the task's log, ``log/<run>/<pkg>/idl/``, and Ctrl+C stops
it), which writes the .msg files, ``roc_idl.cmake`` and protoc's Python modules into
``<build-base>/<pkg>/roc_idl``, rewriting only the files whose text changed (CMake then rebuilds only
what depends on them). The build passes that directory to CMake (``-DROC_IDL_DIR``), and the package's
fingerprint counts the files in it (roc.builder.uptodate), so a change of the generated files rebuilds
the package and its dependents.

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

from roc.builder.environment import base_environment
from roc.builder.fingerprint import FileStamps, changes, source_parts, source_stamps
from roc.builder.state import read_record
from roc.engine.process import TaskContext, TaskError
from roc.fsutil import write_text_atomic

MARKER = "roc_idl"  # the package.xml export, and the output directory in the package's build directory
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


def generated_stamps(source: Path, build_dir: Path) -> FileStamps | None:
    """The stamps of the files the package's ``idl`` task generated; None when it has no protobuf sources."""
    return _outputs(build_dir, {}) if proto_directory(source) is not None else None


def cmake_arguments(build_dir: Path) -> list[str]:
    """What the package's CMake configure needs to find the generated files."""
    return [f"-DROC_IDL_DIR={build_dir / MARKER}"]


@functools.cache
def generator_stamp() -> str:
    """The code generator's identity: roc's IDL modules and protoc (a new roc or protoc generates anew)."""
    from importlib import metadata  # slow to import: only when a workspace has protobuf sources

    digest = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    for distribution in ("grpcio-tools", "protobuf"):
        try:
            digest.update(f"{distribution}=={metadata.version(distribution)}".encode())
        except metadata.PackageNotFoundError:
            pass
    return digest.hexdigest()


def read_state(build_dir: Path) -> dict:
    """The last successful generation's record ({} when there is none; a damaged one is reported)."""
    return read_record(build_dir / STATE_FILE, "damaged code-generation state; the package's code will be "
                       "generated again", ("inputs", "outputs"))


def stale_reasons(source: Path, build_dir: Path, forced: list[str]) -> list[str]:
    """Why the generated files must be made again (empty: up to date)."""
    if forced:
        return list(forced)
    stored = read_state(build_dir)
    if not stored:
        return ["its last code generation did not succeed" if (build_dir / MARKER).exists() else "never generated"]
    inputs, outputs = stored.get("inputs", {}), stored.get("outputs", {})
    before = {"sources": source_parts(inputs), "generated": source_parts(outputs)}
    now = {"sources": source_parts(_inputs(source, inputs)), "generated": source_parts(_outputs(build_dir, outputs))}
    reasons = [reason.replace("generated files removed", "generated files missing") for reason in changes(before, now)]
    if stored.get("generator") != generator_stamp():
        reasons.append("code generator changed")
    return reasons


def _inputs(source: Path, previous: FileStamps) -> FileStamps:
    """The stamps of the package's .proto files, by path relative to the package (as its reasons name
    them: ``files changed: proto/robot/types.proto``)."""
    directory = proto_directory(source)
    if directory is None or not directory.is_dir():
        return {}
    prefix = os.path.relpath(directory, source)
    stamps = source_stamps(directory, {os.path.relpath(path, prefix): stamp for path, stamp in previous.items()})
    return {os.path.normpath(os.path.join(prefix, path)): stamp
            for path, stamp in stamps.items() if path.endswith(".proto")}


def _outputs(build_dir: Path, previous: FileStamps) -> FileStamps:
    out = build_dir / MARKER
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
                str(self.build_dir / MARKER)]

    def run(self, context: TaskContext) -> None:
        state = self.build_dir / STATE_FILE
        # Stamped before generating, so that an edit made during the run shows next time.
        inputs = _inputs(self.source, read_state(self.build_dir).get("inputs", {}))
        self.build_dir.mkdir(parents=True, exist_ok=True)
        state.unlink(missing_ok=True)  # until it succeeds, no old record may vouch for the outputs
        env = base_environment()
        roc_root = str(Path(__file__).resolve().parents[2])  # the code generator of this very roc
        env["PYTHONPATH"] = os.pathsep.join(p for p in (roc_root, env.get("PYTHONPATH")) if p)
        if context.run(self.command(), cwd=str(self.source), env=env) != 0:
            raise TaskError("code generation failed")
        if self.record:
            record = {"generator": generator_stamp(), "inputs": inputs, "outputs": _outputs(self.build_dir, {})}
            write_text_atomic(state, json.dumps(record, separators=(",", ":")))
