"""What a new package is made of: the options, checked and completed with their derived values."""

from __future__ import annotations

import re
from dataclasses import dataclass

from roc.create.names import check_name
from roc.errors import UsageError

# catkin_pkg's rule: a package.xml with another e-mail address does not parse.
_EMAIL = re.compile(r"[-a-zA-Z0-9_%+]+(\.[-a-zA-Z0-9_%+]+)*@[-a-zA-Z0-9%]+(\.[-a-zA-Z0-9%]+)*\.[a-zA-Z]{2,}")
# A dependency of a CMake package is a find_package() name; ament_python ones may be rosdep keys.
_CMAKE_DEPENDENCY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_PYTHON_DEPENDENCY = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*")
# What the example interfaces (msg, srv, action) of --interfaces use.
INTERFACE_DEPENDENCIES = ("builtin_interfaces", "std_msgs")


@dataclass(frozen=True)
class PackageSpec:
    name: str
    build_type: str
    description: str
    license: str
    maintainer_name: str
    maintainer_email: str
    package_format: int = 3
    dependencies: tuple[str, ...] = ()  # as given by the user
    node: str | None = None
    library: str | None = None
    interfaces: bool = False
    tests: bool = False
    version: str = "0.0.0"

    @property
    def python(self) -> bool:
        return self.build_type == "ament_python"

    @property
    def code_dependencies(self) -> tuple[str, ...]:
        """Everything the code finds or imports: the template's own needs first, then the user's."""
        own: tuple[str, ...] = ()
        if self.interfaces:
            own = INTERFACE_DEPENDENCIES
        elif self.node and self.python:
            own = ("rclpy", "std_msgs")
        elif self.node and self.build_type == "ament_cmake":
            own = ("rclcpp", "std_msgs")
        return tuple(dict.fromkeys(own + self.dependencies))

    @property
    def buildtool_dependencies(self) -> tuple[str, ...]:
        if self.interfaces:
            return ("ament_cmake", "rosidl_default_generators")
        if self.build_type == "ament_cmake":
            # ament_cmake_ros makes libraries shared by default (BUILD_SHARED_LIBS), as ros2 pkg create does.
            return ("ament_cmake", "ament_cmake_ros") if self.library else ("ament_cmake",)
        return ("cmake",) if self.build_type == "cmake" else ()

    @property
    def depends(self) -> tuple[str, ...]:
        """The ``<depend>`` entries of package.xml (actions also need action_msgs there)."""
        return self.code_dependencies + (("action_msgs",) if self.interfaces else ())

    @property
    def test_dependencies(self) -> tuple[str, ...]:
        if not self.tests or self.build_type == "cmake":
            return ()
        if self.python:
            return ("python3-pytest",)
        return ("ament_cmake_gtest",) if self.library else ("ament_cmake_pytest",)


def check_spec(spec: PackageSpec) -> None:
    """Every value that ends up in a generated file is valid (raises a usage error otherwise)."""
    check_name("package", spec.name)
    for kind, value in (("node", spec.node), ("library", spec.library)):
        if value is not None:
            check_name(kind, value)
    if spec.interfaces:
        if spec.build_type != "ament_cmake":
            raise UsageError("--interfaces makes an ament_cmake package; leave out --build-type "
                             f"{spec.build_type}")
        if spec.node or spec.library:
            raise UsageError("--interfaces cannot be combined with --node-name or --library-name: "
                             "put code in another package that depends on the interfaces")
        if spec.package_format < 3:
            raise UsageError("--interfaces needs --package-format 3 (for <member_of_group>)")
    if spec.python and spec.name == "test":
        raise UsageError("an ament_python package cannot be named 'test' (its tests live in test/)")
    pattern = _PYTHON_DEPENDENCY if spec.python else _CMAKE_DEPENDENCY
    for dependency in spec.dependencies:
        if not pattern.fullmatch(dependency):
            expected = "a package name or rosdep key" if spec.python else "a CMake package name for find_package()"
            raise UsageError(f"dependency '{dependency}' is not {expected}")
    if spec.name in spec.dependencies:
        raise UsageError(f"package '{spec.name}' cannot depend on itself")
    if not spec.description.strip():
        raise UsageError("--description must not be empty")
    if not spec.license.strip():
        raise UsageError("--license must not be empty")
    if not spec.maintainer_name.strip():
        raise UsageError("--maintainer-name must not be empty")
    if not _EMAIL.fullmatch(spec.maintainer_email):
        raise UsageError(f"'{spec.maintainer_email}' is not a valid e-mail address for package.xml "
                         "(set --maintainer-email)")
