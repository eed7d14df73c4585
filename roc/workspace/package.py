"""The package descriptor shared by every verb.

A plain class rather than a dataclass: importing dataclasses costs more than listing a workspace
from the discovery cache.
"""

from __future__ import annotations

from pathlib import Path

TYPE_CHECKING = False  # typing is not imported at run time (start-up time of every verb)
if TYPE_CHECKING:
    from roc.workspace.manifest import Manifest

CATEGORIES = ("build", "run", "test")
# Files whose presence makes discovery skip a directory and everything below it.
IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
# ``Manifest`` (roc.workspace.manifest) appears in annotations only; it is imported where a manifest is
# decoded, not here, so that listing a workspace from the cache never loads it.


class Package:
    """One package found in a workspace.

    ``path`` is as colcon prints it: the base path joined with the package's directory below it.
    ``dependencies`` maps each category (build, run, test) to the names of the packages depended on;
    names outside the workspace are kept (they are satisfied by underlays). Only the categories the
    package's kind defines are present (colcon info prints them). ``constraints`` holds version
    constraints of dependencies, e.g. {"rclpy": {"version_gte": "3.0"}}; ``manifest`` the parsed
    package.xml of ROS packages.
    """

    def __init__(
        self, name: str, path: Path | str, type: str, dependencies: dict[str, set[str]] | None = None,  # noqa: A002
        hooks: list[str] | None = None, metadata: dict[str, object] | None = None,
        constraints: dict[str, dict[str, str]] | None = None, group_depends: list[str] | None = None,
        member_of_groups: list[str] | None = None, manifest: Manifest | None = None,
    ):
        self.name = name
        self._path: Path | str = path  # a str from the discovery cache, made a Path on first use
        self.type = type  # ros.ament_cmake, ros.ament_python, ros.cmake, ros.catkin, cmake, python, ...
        self.dependencies = dependencies if dependencies is not None else {}
        self.hooks = hooks if hooks is not None else []
        self.metadata = metadata if metadata is not None else {}
        self.constraints = constraints if constraints is not None else {}
        self.group_depends = group_depends if group_depends is not None else []
        self.member_of_groups = member_of_groups if member_of_groups is not None else []
        self._manifest = manifest
        # from the discovery cache, decoded on first use: a dict, or marshal bytes of one (a command that
        # needs no manifest, such as `roc work list`, then never decodes a thousand of them)
        self._manifest_data: dict | bytes | None = None

    @property
    def manifest(self) -> Manifest | None:  # noqa: F821
        if self._manifest is None and self._manifest_data is not None:
            import marshal

            from roc.workspace.manifest import Manifest

            data = self._manifest_data
            self._manifest = Manifest.from_dict(marshal.loads(data) if isinstance(data, bytes) else data)
            self._manifest_data = None
        return self._manifest

    @manifest.setter
    def manifest(self, value: Manifest | None) -> None:  # noqa: F821
        self._manifest, self._manifest_data = value, None

    @property
    def path(self) -> Path:
        if not isinstance(self._path, Path):
            self._path = Path(self._path)
        return self._path

    @path.setter
    def path(self, value: Path) -> None:
        self._path = value

    @property
    def path_text(self) -> str:
        """``path`` as colcon prints it, without making a Path of a cached one."""
        return self._path if isinstance(self._path, str) else str(self._path)

    def __repr__(self) -> str:
        return f"Package({self.name!r}, {str(self.path)!r}, {self.type!r})"

    def direct_dependencies(self, categories=CATEGORIES) -> set[str]:
        names: set[str] = set()
        for category in categories:
            names |= self.dependencies.get(category, set())
        names.discard(self.name)
        return names

    def to_dict(self) -> dict:
        """A JSON-ready form (for the discovery cache)."""
        return {
            "name": self.name, "path": str(self.path), "type": self.type,
            "dependencies": {c: sorted(names) for c, names in self.dependencies.items()},
            "hooks": self.hooks, "metadata": self.metadata, "constraints": self.constraints,
            "group_depends": self.group_depends, "member_of_groups": self.member_of_groups,
            "manifest": self.manifest.to_dict() if self.manifest else None,
        }

    @classmethod
    def from_dict(cls, data: dict) -> Package:
        package = cls(
            name=data["name"], path=data["path"], type=data["type"],
            dependencies={c: set(names) for c, names in data["dependencies"].items()},
            hooks=data["hooks"], metadata=data["metadata"], constraints=data["constraints"],
            group_depends=data["group_depends"], member_of_groups=data["member_of_groups"],
        )
        package._manifest_data = data["manifest"]
        return package

    @property
    def build_type(self) -> str:
        """The type without the ``ros.`` prefix: ament_cmake, ament_python, cmake, python, ..."""
        return self.type.split(".", 1)[-1]
