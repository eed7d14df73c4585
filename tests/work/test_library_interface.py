"""A shared library's interface (roc.builder.interface): what changes it and what does not, on libraries
gcc builds."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from roc.builder.interface import install_interface, library_interface
from roc.buildtypes.context import BuildOptions

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")


def _library(directory: Path, source: str, name: str = "libdemo.so", *flags: str) -> str:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "demo.c").write_text(source)
    output = directory / name
    subprocess.run(["gcc", "-shared", "-fPIC", *flags, "-o", str(output), str(directory / "demo.c")], check=True)
    return str(output)


BASE = "int demo_table[4];\nint demo_value(void) { return 42; }\n"


def test_an_implementation_change_keeps_the_interface(tmp_path: Path) -> None:
    before = library_interface(_library(tmp_path / "a", BASE))
    after = library_interface(_library(tmp_path / "b", BASE.replace("42", "43 + demo_table[1]")))
    assert before is not None and before == after


@pytest.mark.parametrize("changed", [
    BASE + "int demo_extra(void) { return 1; }\n",  # a symbol added
    BASE.replace("demo_value", "demo_renamed"),  # a symbol renamed
    BASE.replace("demo_table[4]", "demo_table[8]"),  # a data object resized (programs copy it)
])
def test_an_exported_symbol_change_changes_the_interface(tmp_path: Path, changed: str) -> None:
    assert library_interface(_library(tmp_path / "a", BASE)) != library_interface(_library(tmp_path / "b", changed))


def test_a_new_soname_changes_the_interface(tmp_path: Path) -> None:
    plain = library_interface(_library(tmp_path / "a", BASE))
    named = library_interface(_library(tmp_path / "b", BASE, "libdemo.so", "-Wl,-soname,libdemo.so.2"))
    assert plain != named


def test_programs_and_other_files_have_no_library_interface(tmp_path: Path) -> None:
    (tmp_path / "main.c").write_text("int main(void) { return 0; }\n")
    program = tmp_path / "program.so"  # a position-independent program named like a library
    subprocess.run(["gcc", "-fPIE", "-pie", "-o", str(program), str(tmp_path / "main.c")], check=True)
    (tmp_path / "text.so").write_text("not ELF")
    assert library_interface(str(program)) is None
    assert library_interface(str(tmp_path / "text.so")) is None


def _install(tmp_path: Path, library_source: str, header: str) -> str:
    """A package 'demo' installed in its own prefix (a library and a header)."""
    prefix = tmp_path / "install" / "demo"
    library = _library(tmp_path / "objects", library_source)
    (prefix / "lib").mkdir(parents=True, exist_ok=True)
    (prefix / "include").mkdir(parents=True, exist_ok=True)
    shutil.copy(library, prefix / "lib" / "libdemo.so")
    (prefix / "include" / "demo.h").write_text(header)
    options = BuildOptions(build_base=tmp_path / "build", install_base=tmp_path / "install")
    return install_interface("demo", tmp_path, options)


def test_an_install_counts_libraries_by_interface_and_other_files_by_content(tmp_path: Path) -> None:
    header = "int demo_value(void);\n"
    first = _install(tmp_path, BASE, header)
    assert _install(tmp_path, BASE.replace("42", "7"), header) == first
    assert _install(tmp_path, BASE, header + "/* a comment */\n") != first
    hooks = tmp_path / "install" / "demo" / "share" / "demo" / "hook"
    hooks.mkdir(parents=True)
    (hooks / "path.dsv").write_text("prepend-non-duplicate;PATH;bin\n")
    assert _install(tmp_path, BASE, header) != first  # an environment hook roc wrote
