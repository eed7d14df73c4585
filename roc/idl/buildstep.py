"""The code-generation step of ``roc work build`` for packages with protobuf sources (see roc.idl.codegen):
run before CMake, it regenerates the .msg files in the build directory and hands CMake their location."""

from __future__ import annotations

import sys
from pathlib import Path

MARKER = "roc_idl"


def proto_directory(source: Path) -> Path | None:
    """The package's protobuf source directory, when its package.xml exports ``<roc_idl>DIR</roc_idl>``."""
    manifest = source / "package.xml"
    if not manifest.is_file():
        return None
    from lxml import etree

    element = etree.parse(str(manifest)).find(f"export/{MARKER}")
    return source / (element.text or "proto").strip() if element is not None else None


def command(name: str, source: Path, build_dir: Path) -> tuple[list[str], str] | None:
    """The step's command and the CMake argument that points the package at its output, or None."""
    directory = proto_directory(source)
    if directory is None:
        return None
    out = build_dir / MARKER
    return [sys.executable, "-m", "roc.idl.codegen", name, str(directory), str(out)], f"-DROC_IDL_DIR={out}"
