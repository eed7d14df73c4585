"""``roc idl protobuf FILES...``: convert .proto files to ROS 2 .msg files, or .msg files to .proto."""

from __future__ import annotations

import argparse
from pathlib import Path

from roc.errors import RocError, UsageError
from roc.render import print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("files", nargs="+", metavar="FILE", help=".proto files (to .msg) or .msg files (to .proto)")
    parser.add_argument("-o", "--output", type=Path, default=Path("."), metavar="DIR",
                        help="output directory (default: the current one)")
    parser.add_argument("-p", "--package", metavar="NAME",
                        help="package for files without one (proto: no 'package' line; msg: not in <pkg>/msg/)")
    parser.add_argument("-I", "--include", type=Path, action="append", default=[], metavar="DIR",
                        help="import root (repeatable); default: each file's directory")
    parser.add_argument("-c", "--config", type=Path, metavar="FILE",
                        help="YAML with type mappings and renames (keys: types, fields, renames, packages)")
    parser.add_argument("--ros-package", action="store_true",
                        help=".proto -> .msg: also write package.xml and CMakeLists.txt, so each package builds")
    parser.add_argument("-v", "--verbose", action="store_true", help="also print each file's content and notes")
    parser.add_argument("-n", "--dry-run", action="store_true", help="print what would be written, write nothing")


def direction(files: list[Path]) -> str:
    suffixes = {path.suffix for path in files}
    for path in files:
        if path.suffix not in (".proto", ".msg"):
            raise RocError(f"{path}: unknown extension '{path.suffix}': expected .proto or .msg")
    if len(suffixes) > 1:
        raise RocError(f"{files[0]} and {next(p for p in files if p.suffix != files[0].suffix)}: "
                       "mixed .proto and .msg files: convert one direction at a time")
    for path in files:
        if not path.is_file():
            raise RocError(f"{path}: no such file")
    return suffixes.pop()


def convert(files: list[Path], output: Path, package: str | None, includes: list[Path],
            config_path: Path | None) -> tuple[dict[str, str], list[str]]:
    """Output files (relative path -> text) and notes; nothing is written here."""
    from roc.idl import config

    settings = config.load(config_path)
    if direction(files) == ".proto":
        from roc.idl import proto_to_msg, protoc

        roots = protoc.include_roots(files, includes)
        targets = [next(str(p.resolve().relative_to(r)) for r in roots if p.resolve().is_relative_to(r))
                   for p in files]
        return proto_to_msg.convert(protoc.descriptor_set(files, includes), targets, settings, package)
    from roc.idl import msg_to_proto

    return msg_to_proto.convert(files, package, settings, [output, *includes]), []


def run(args: argparse.Namespace) -> int:
    from roc.fsutil import write_text_atomic

    files = [Path(f) for f in args.files]
    outputs, notes = convert(files, args.output, args.package, args.include, args.config)
    if args.ros_package:
        if direction(files) != ".proto":
            raise UsageError("--ros-package: only for .proto -> .msg")
        from roc.idl.package import package_files

        outputs.update(package_files(outputs))
    lines = []
    for relative, text in sorted(outputs.items()):
        target = args.output / relative
        lines.append(f"{'would write' if args.dry_run else 'wrote'} {target}")
        if args.verbose:
            lines += [f"    {line}" for line in text.splitlines()]
    if args.verbose:
        lines += [f"note: {note}" for note in notes]
    if not args.dry_run:
        for relative, text in outputs.items():
            write_text_atomic(args.output / relative, text)
    print_lines(lines)
    return 0
