"""``roc work create NAME``: a new package from templates, like ``ros2 pkg create`` (same options)."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from roc.errors import RocError, UsageError

if TYPE_CHECKING:
    from roc.create.spec import PackageSpec

BUILD_TYPES = ("ament_cmake", "ament_python", "cmake")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("name", metavar="NAME", help="the package name (REP 144: e.g. my_robot_driver)")
    parser.add_argument("--build-type", choices=BUILD_TYPES, default=None,
                        help="the package's build type (default: ament_cmake)")
    parser.add_argument("--dependencies", nargs="+", default=[], metavar="DEP",
                        help="packages it depends on (package.xml <depend>, find_package() in CMake)")
    parser.add_argument("--node-name", metavar="NAME",
                        help="add a node that publishes on 'chatter' (rclpy, or rclcpp for ament_cmake; "
                             "a plain program for cmake)")
    parser.add_argument("--library-name", metavar="NAME",
                        help="add a library (a C++ library exported for find_package(), or a Python module)")
    parser.add_argument("--license", metavar="SPDX", default=None,
                        help="the licence, as an SPDX id; known ones also get a LICENSE file "
                             "('?' lists them; default: 'TODO: License declaration')")
    parser.add_argument("--maintainer-name", metavar="NAME",
                        help="maintainer name (default: git config user.name, else the login name)")
    parser.add_argument("--maintainer-email", metavar="EMAIL",
                        help="maintainer e-mail (default: git config user.email, else <login>@todo.todo)")
    parser.add_argument("--description", default="TODO: Package description",
                        help="the package.xml description (default: 'TODO: Package description')")
    parser.add_argument("--package-format", type=int, choices=(2, 3), default=3,
                        help="the package.xml format (default: 3)")
    parser.add_argument("--destination-directory", metavar="DIR",
                        help="where the package directory goes (default: the workspace's src/ inside a "
                             "workspace, else the current directory)")
    parser.add_argument("--parents", action="store_true",
                        help="roc: create the missing parent directories of --destination-directory")
    parser.add_argument("--interfaces", action="store_true",
                        help="roc: an interface package (example msg, srv and action; ament_cmake with rosidl)")
    parser.add_argument("--tests", action="store_true",
                        help="roc: add tests (pytest for Python packages; gtest of the library, else pytest, "
                             "for ament_cmake; CTest for cmake)")


def run(args: argparse.Namespace) -> int:
    from roc.create import licenses

    if args.license == "?":
        print("\n".join(licenses.KNOWN))
        return 0
    spec, notes = _spec(args)
    destination = _destination(args.destination_directory, args.parents)
    _check_name_is_free(spec.name, destination)

    from roc.create.render import render_package
    from roc.create.write import write_package

    target = write_package(destination, spec.name, render_package(spec))
    for note in notes:
        print(f"roc: note: {note}", file=sys.stderr)
    print(f"created package {spec.name} ({spec.build_type}) in {_shown(target)}:")
    print("".join(f"  {path}\n" for path in _files(target)), end="")
    return 0


def _spec(args: argparse.Namespace) -> tuple[PackageSpec, list[str]]:
    """The checked package spec, and the notes to print once it is written."""
    from roc.create import licenses
    from roc.create.maintainer import default_maintainer
    from roc.create.spec import PackageSpec, check_spec

    notes: list[str] = []
    node = args.node_name
    if node is not None and node == args.library_name:
        node = f"{node}_node"
        notes.append(f"the node cannot have the library's name: it is called '{node}'")
    license_id = licenses.DEFAULT if args.license is None else licenses.canonical(args.license)
    if args.license is None:
        notes.append(f"no --license given: package.xml says '{licenses.DEFAULT}' and there is no LICENSE file")
    elif license_id not in licenses.KNOWN:
        notes.append(f"licence '{license_id}' is in package.xml but no LICENSE file was written "
                     f"(known SPDX ids: {', '.join(licenses.KNOWN)})")
    name, email = default_maintainer(args.maintainer_name, args.maintainer_email)
    spec = PackageSpec(
        name=args.name, build_type=args.build_type or "ament_cmake", description=args.description,
        license=license_id, maintainer_name=name, maintainer_email=email, package_format=args.package_format,
        dependencies=tuple(dict.fromkeys(args.dependencies)), node=node, library=args.library_name,
        interfaces=args.interfaces, tests=args.tests,
    )
    check_spec(spec)
    return spec, notes


def _destination(option: str | None, parents: bool) -> Path:
    if option is not None:
        destination = Path(option).absolute()
        if not parents and not destination.parent.is_dir():
            raise UsageError(f"--destination-directory {option}: {destination.parent} does not exist; "
                             "create it, or add --parents to create the missing directories")
        return destination
    from roc.workspace.root import find_workspace_root

    root = find_workspace_root(Path.cwd())
    return root / "src" if root is not None else Path.cwd()


def _check_name_is_free(name: str, destination: Path) -> None:
    """A workspace cannot hold two packages of one name: refuse before writing anything."""
    from roc.workspace.load import discover_workspace
    from roc.workspace.root import find_workspace_root

    root = find_workspace_root(destination)
    if root is None:
        return
    try:
        packages = discover_workspace(root)
    except RocError:  # a workspace that cannot be read (a broken package.xml) is no reason not to create
        return
    same = next((p for p in packages if p.name == name), None)
    if same is not None:
        raise UsageError(f"the workspace {root} already has a package named '{name}' (in {root / same.path}); "
                         "choose another name")


def _shown(path: Path) -> str:
    relative = os.path.relpath(path)
    return path.as_posix() if relative.startswith("..") else relative


def _files(directory: Path) -> list[str]:
    return sorted(p.relative_to(directory).as_posix() for p in directory.rglob("*") if p.is_file())
