"""Render the files of a new package from the jinja2 templates in ``templates/``.

Templates insert free text only through the ``xml`` and ``py`` filters; every name they insert was
checked by ``roc.create.spec.check_spec`` (so it is safe in CMake, C++, XML and Python).
"""

from __future__ import annotations

from functools import lru_cache
from xml.sax.saxutils import escape

from roc.create.licenses import license_text
from roc.create.spec import PackageSpec
from roc.templates import template_environment


@lru_cache(maxsize=1)
def _templates():
    return template_environment("roc.create", {
        "xml": lambda value: escape(str(value), {'"': "&quot;", "'": "&apos;"}),
        "py": lambda value: repr(str(value)),
        "ref": lambda name: "${" + name + "}",  # a CMake variable reference
        "camel": lambda value: "".join(part.capitalize() for part in value.split("_")),
    }, trim_blocks=True, lstrip_blocks=True)


def _plan(spec: PackageSpec) -> list[tuple[str, str]]:
    """(file in the package, template) pairs."""
    name, node, library = spec.name, spec.node, spec.library
    files = [("package.xml", "package.xml.j2")]
    if spec.interfaces:
        files += [("CMakeLists.txt", "interfaces/CMakeLists.txt.j2"),
                  ("msg/Greeting.msg", "interfaces/Greeting.msg.j2"),
                  ("srv/SetGreeting.srv", "interfaces/SetGreeting.srv.j2"),
                  ("action/Countdown.action", "interfaces/Countdown.action.j2")]
        if spec.tests:
            files.append(("test/test_interfaces.py", "interfaces/test_interfaces.py.j2"))
        return files
    if spec.python:
        files += [("setup.py", "python/setup.py.j2"), ("setup.cfg", "python/setup.cfg.j2"),
                  (f"resource/{name}", "python/resource.j2"), (f"{name}/__init__.py", "python/__init__.py.j2")]
        if node:
            files.append((f"{name}/{node}.py", "python/node.py.j2"))
        if library:
            files.append((f"{name}/{library}.py", "python/library.py.j2"))
        if spec.tests:
            files.append((f"test/test_{name}.py", "python/test_package.py.j2"))
        return files
    files.append(("CMakeLists.txt", f"{spec.build_type}/CMakeLists.txt.j2"))
    if library:
        files += [(f"include/{name}/{library}.hpp", "cpp/library.hpp.j2"),
                  (f"include/{name}/visibility_control.h", "cpp/visibility_control.h.j2"),
                  (f"src/{library}.cpp", "cpp/library.cpp.j2")]
    if node:
        node_template = "cpp/rclcpp_node.cpp.j2" if spec.build_type == "ament_cmake" else "cpp/main.cpp.j2"
        files.append((f"src/{node}.cpp", node_template))
    if spec.build_type == "cmake":
        if library:
            files.append((f"cmake/{name}Config.cmake.in", "cmake/Config.cmake.in.j2"))
        if spec.tests:
            files.append((f"test/test_{library or name}.cpp", "cmake/test.cpp.j2"))
    elif spec.tests:
        files.append((f"test/test_{library}.cpp", "cpp/test_library_gtest.cpp.j2") if library else
                     (f"test/test_{name}.py", "ament_cmake/test_package.py.j2"))
    return files


def render_package(spec: PackageSpec) -> dict[str, str]:
    """Every file of the package: path in the package -> text."""
    environment = _templates()
    files = {path: environment.get_template(template).render(spec=spec) for path, template in _plan(spec)}
    text = license_text(spec.license, spec.maintainer_name)
    if text is not None:
        files["LICENSE"] = text
    return files
