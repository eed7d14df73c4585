"""What a package's dependents build against: its installed files, each shared library counted by its
interface (its soname, the libraries it needs, the symbols it exports) rather than by its bytes.

A dependent is rebuilt when a dependency's interface changes, not whenever its sources do: after an edit
inside a library's implementation (a .cpp file), the programs of the packages above it would link the
same symbols by the same name and load the new library at run time, so rebuilding them would make the
same files. Chromium's builds skip such relinks by the same rule (a library's "table of contents"), as
Bazel does with interface shared objects. Everything else a package installs (headers, CMake files,
static libraries, programs, Python modules, the environment hooks) counts by its content.
"""

from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path

from roc.builder.layout import package_prefix
from roc.buildtypes.context import BuildOptions
from roc.fsutil import file_sha256

SHARED_LIBRARY = re.compile(r"\.so(\.\d+)*$")
# A data object's size is part of the interface: a program that copies it (a copy relocation) is
# linked with its size.
SIZED = ("STT_OBJECT", "STT_TLS")


def library_interface(path: str) -> str | None:
    """A shared library's soname, needed libraries and exported symbols (with the size of each data
    object), as one digest; None when the file is not a shared library (a program is an ELF shared
    object too when position-independent: it names an interpreter)."""
    from elftools.common.exceptions import ELFError
    from elftools.elf.dynamic import DynamicSection
    from elftools.elf.elffile import ELFFile
    from elftools.elf.sections import SymbolTableSection

    try:
        with open(path, "rb") as stream:
            if stream.read(4) != b"\x7fELF":
                return None
            stream.seek(0)
            elf = ELFFile(stream)
            if elf["e_type"] != "ET_DYN" or any(s["p_type"] == "PT_INTERP" for s in elf.iter_segments()):
                return None
            lines = []
            for section in elf.iter_sections():
                if isinstance(section, DynamicSection):
                    lines += [f"{tag.entry.d_tag}={getattr(tag, 'soname', None) or getattr(tag, 'needed', '')}"
                              for tag in section.iter_tags() if tag.entry.d_tag in ("DT_SONAME", "DT_NEEDED")]
                elif isinstance(section, SymbolTableSection) and section.name == ".dynsym":
                    symbols = []
                    for symbol in section.iter_symbols():
                        info = symbol["st_info"]
                        if symbol["st_shndx"] == "SHN_UNDEF" or info["bind"] == "STB_LOCAL":
                            continue
                        size = symbol["st_size"] if info["type"] in SIZED else ""
                        symbols.append(f"{symbol.name} {info['type']} {info['bind']} {size}")
                    lines += sorted(symbols)
    except (OSError, ELFError, ValueError):
        return None  # not readable as ELF: counted by its bytes
    return hashlib.sha256("\n".join(lines).encode()).hexdigest()


def _file_part(path: str) -> str:
    if os.path.islink(path):
        target = os.readlink(path)
        resolved = os.path.realpath(path)
        return f"-> {target} {_file_part(resolved) if os.path.isfile(resolved) else 'dangling'}"
    if not os.path.isfile(path):
        return "missing" if not os.path.isdir(path) else "directory"
    if SHARED_LIBRARY.search(path):
        interface = library_interface(path)
        if interface is not None:
            return f"library {interface}"
    return file_sha256(Path(path))


def install_interface(name: str, root: Path, options: BuildOptions) -> str:
    """The interface of package ``name``'s install in workspace ``root``: every file it installed
    (roc.builder.artefact.installed_files: its records, the hooks and scripts roc wrote for it)."""
    from roc.builder.artefact import Places, installed_files  # not on a no-op build's path (dataclasses)

    prefix = package_prefix(options.install_base, name, options.merge_install)
    places = Places(root, options.build_base, options.install_base)
    digest = hashlib.sha256()
    for path in installed_files(name, places, options.merge_install):
        if path.suffix == ".pyc":  # written when Python first imports a module, not by the build
            continue
        digest.update(f"{path.relative_to(prefix)}\0{_file_part(str(path))}\0".encode())
    return digest.hexdigest()
