"""The real protobuf compiler (grpcio-tools' protoc, run in-process) as a parser and a checker."""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path
from types import ModuleType

from roc.errors import RocError


def protoc_module() -> ModuleType:
    """grpcio-tools' protoc. grpcio-tools is roc's idl extra, not a dependency: it needs setuptools>=77,
    which colcon and ROS's Python packages do not take. Missing, a one-line RocError says how to install it."""
    try:
        from grpc_tools import protoc
    except ImportError:
        raise RocError("protoc is not installed: roc idl and .proto sources need grpcio-tools (roc's idl extra): "
                       f"{sys.executable} -m pip install grpcio-tools (pipx: pipx inject roc-ros2 grpcio-tools)") \
            from None
    return protoc


def well_known_include() -> str:
    """The directory holding google/protobuf/*.proto, bundled with grpcio-tools."""
    from importlib import resources

    protoc_module()
    return str(resources.files("grpc_tools") / "_proto")


def run(arguments: list[str]) -> tuple[int, str]:
    """Run protoc with ``arguments``; its exit code and what it printed (it writes to fd 2 directly)."""
    protoc = protoc_module()
    with tempfile.TemporaryFile(mode="w+") as captured:
        saved = os.dup(2)
        os.dup2(captured.fileno(), 2)
        try:
            code = protoc.main(["protoc", *arguments])
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        captured.seek(0)
        return code, captured.read().strip()


def include_roots(files: list[Path], includes: list[Path]) -> list[Path]:
    """The import roots: ``-I`` directories, else each file's directory."""
    roots = [p.resolve() for p in includes]
    for path in files:
        if not any(path.resolve().is_relative_to(root) for root in roots):
            roots.append(path.resolve().parent)
    return roots


def descriptor_set(files: list[Path], includes: list[Path]):
    """Compile ``files`` into a ``FileDescriptorSet`` (with imports and source info); protoc's first
    error becomes a one-line RocError naming file:line."""
    from google.protobuf import descriptor_pb2

    roots = include_roots(files, includes)
    with tempfile.TemporaryDirectory(prefix="roc-idl-") as temporary:
        out = Path(temporary) / "set.pb"
        arguments = [f"-I{root}" for root in roots] + [f"-I{well_known_include()}"]
        arguments += [f"--descriptor_set_out={out}", "--include_imports", "--include_source_info"]
        code, errors = run(arguments + [str(p.resolve()) for p in files])
        if code != 0:
            raise RocError(_first_error(errors) or "protoc failed")
        result = descriptor_pb2.FileDescriptorSet()
        result.ParseFromString(out.read_bytes())
        return result


def check(directory: Path, names: list[str], includes: list[Path]) -> None:
    """Compile the .proto files ``names`` under ``directory`` (a check that they are valid)."""
    with tempfile.TemporaryDirectory(prefix="roc-idl-") as temporary:
        arguments = [f"-I{directory}"] + [f"-I{p}" for p in includes] + [f"-I{well_known_include()}"]
        arguments += [f"--descriptor_set_out={Path(temporary) / 'set.pb'}"]
        code, errors = run(arguments + names)
        if code != 0:
            raise RocError(f"generated .proto does not compile: {_first_error(errors)}")


def _first_error(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip() and "warning:" not in line]
    return lines[0] if lines else ""
