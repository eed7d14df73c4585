"""roc pkg xml: a package's manifest as installed, or the text of each element of one tag (like ros2 pkg
xml: the manifest re-serialised, without its XML declaration and comments)."""

from __future__ import annotations

import argparse

from roc.cli.options import add_format_argument
from roc.errors import RocError
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package_name", metavar="PKG", help="the package name")
    parser.add_argument("-t", "--tag", help="print only the text of the elements of this tag (e.g. 'version')")
    add_format_argument(parser)


def run(args: argparse.Namespace) -> int:
    import xml.etree.ElementTree as ET

    from roc.ament_index import share_directory

    manifest = share_directory(args.package_name) / "package.xml"
    if not manifest.is_file():
        raise RocError(f"package '{args.package_name}' has no installed manifest: {manifest} does not exist")
    try:
        root = ET.parse(manifest).getroot()
    except ET.ParseError as error:
        raise RocError(f"{manifest}: invalid XML: {error}") from None
    if args.tag is None:
        text = ET.tostring(root, encoding="unicode")
        if not root.tail or not root.tail.endswith("\n"):
            text += "\n"
        render({"package": args.package_name, "path": str(manifest), "xml": text}, args.format, [text.rstrip("\n")])
        return 0
    elements = root.findall(args.tag)
    if not elements:
        tags = sorted({child.tag for child in root if isinstance(child.tag, str)})
        raise RocError(f"{manifest}: no <{args.tag}> element (tags: {', '.join(tags)})")
    values = [element.text or "" for element in elements]
    render({"package": args.package_name, "tag": args.tag, "values": values}, args.format, values)
    return 0
