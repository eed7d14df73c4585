"""The package descriptor shared by every verb."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from roc.workspace.manifest import Manifest

CATEGORIES = ("build", "run", "test")


@dataclass(eq=False)
class Package:
    """One package found in a workspace.

    ``path`` is as colcon prints it: the base path joined with the package's directory below it.
    ``dependencies`` maps each category (build, run, test) to the names of the packages depended on;
    names outside the workspace are kept (they are satisfied by underlays).
    """

    name: str
    path: Path
    type: str  # ros.ament_cmake, ros.ament_python, ros.cmake, ros.catkin, cmake, python, ...
    # Only the categories the package's kind defines are present (colcon info prints them).
    dependencies: dict[str, set[str]] = field(default_factory=dict)
    hooks: list[str] = field(default_factory=list)
    metadata: dict[str, object] = field(default_factory=dict)
    # Version constraints of dependencies, e.g. {"rclpy": {"version_gte": "3.0"}}.
    constraints: dict[str, dict[str, str]] = field(default_factory=dict)
    group_depends: list[str] = field(default_factory=list)
    member_of_groups: list[str] = field(default_factory=list)
    manifest: Manifest | None = None  # the parsed package.xml of ROS packages

    def direct_dependencies(self, categories=CATEGORIES) -> set[str]:
        names: set[str] = set()
        for category in categories:
            names |= self.dependencies.get(category, set())
        names.discard(self.name)
        return names

    @property
    def build_type(self) -> str:
        """The type without the ``ros.`` prefix: ament_cmake, ament_python, cmake, python, ..."""
        return self.type.split(".", 1)[-1]
