"""Parse ROS ``package.xml`` manifests (formats 1, 2 and 3) with lxml.

Only what roc needs is kept; conditions (REP 149) are evaluated here so that callers see the
dependencies that apply to the current environment, as colcon does.
"""

from __future__ import annotations

import re
from collections import namedtuple
from collections.abc import Mapping
from pathlib import Path

from roc.errors import ManifestError
from roc.workspace.conditions import ConditionError, evaluate_condition

VERSION_ATTRIBUTES = ("version_lt", "version_lte", "version_eq", "version_gte", "version_gt")

# Which dependency tag feeds which of the tag lists of REP 140 (format 2/3) and REP 127 (format 1).
_TAG_EXPANSION = {
    "depend": ("build_depend", "build_export_depend", "exec_depend"),
    "run_depend": ("build_export_depend", "exec_depend"),
}
_TAGS_BY_FORMAT = {
    1: ("build_depend", "buildtool_depend", "run_depend", "test_depend"),
    2: ("depend", "build_depend", "build_export_depend", "buildtool_depend", "buildtool_export_depend",
        "exec_depend", "test_depend", "doc_depend"),
}
_TAGS_BY_FORMAT[3] = _TAGS_BY_FORMAT[2] + ("group_depend", "member_of_group")
# colcon-ros' dependency categories, from the expanded tag lists.
CATEGORY_TAGS = {
    "build": ("build_depend", "buildtool_depend"),
    "run": ("build_export_depend", "buildtool_export_depend", "exec_depend"),
    "test": ("test_depend",),
}


# ``tag`` as written (``depend``, ``run_depend``, ...); ``versions``: (attribute, value) pairs such as
# ("version_gte", "1.2").
Dependency = namedtuple("Dependency", "name tag versions condition", defaults=((), None))


class Manifest:
    """A parsed package.xml (a plain class: see roc.workspace.package)."""

    FIELDS = ("path", "format", "name", "version", "description", "maintainers", "authors", "licenses", "urls",
              "build_type", "dependencies", "group_depends", "member_of_groups", "condition_variables")

    def __init__(self, path: Path, format: int, name: str, version: str, description: str = "",  # noqa: A002
                 build_type: str = "catkin", **lists):
        self.path = path
        self.format = format
        self.name = name
        self.version = version
        self.description = description
        self.build_type = build_type
        self.maintainers: list[str] = lists.pop("maintainers", [])  # "Name <email>"
        self.authors: list[str] = lists.pop("authors", [])
        self.licenses: list[str] = lists.pop("licenses", [])
        self.urls: list[tuple[str, str]] = lists.pop("urls", [])  # (type, url)
        self.dependencies: list[Dependency] = lists.pop("dependencies", [])  # only those whose condition holds
        self.group_depends: list[str] = lists.pop("group_depends", [])
        self.member_of_groups: list[str] = lists.pop("member_of_groups", [])
        self.condition_variables: list[str] = lists.pop("condition_variables", [])  # $NAMEs conditions read
        if lists:
            raise TypeError(f"unknown manifest fields: {', '.join(lists)}")

    def to_dict(self) -> dict:
        data = {f: getattr(self, f) for f in self.FIELDS}
        data["path"] = str(self.path)
        data["dependencies"] = [[d.name, d.tag, [list(v) for v in d.versions], d.condition] for d in self.dependencies]
        return data

    @classmethod
    def from_dict(cls, data: dict) -> Manifest:
        values = dict(data, path=Path(data["path"]), urls=[tuple(u) for u in data["urls"]])
        values["dependencies"] = [Dependency(name, tag, tuple(tuple(v) for v in versions), condition)
                                  for name, tag, versions, condition in data["dependencies"]]
        return cls(**values)

    def dependencies_by_tag(self, tag: str) -> list[Dependency]:
        """Dependencies of an expanded tag list (``depend`` counts as build, build_export and exec)."""
        return [d for d in self.dependencies if d.tag == tag or tag in _TAG_EXPANSION.get(d.tag, ())]

    def category_dependencies(self) -> dict[str, dict[str, Dependency]]:
        """Dependencies grouped as colcon-ros groups them: build, run and test."""
        result: dict[str, dict[str, Dependency]] = {}
        for category, tags in CATEGORY_TAGS.items():
            result[category] = {d.name: d for tag in tags for d in self.dependencies_by_tag(tag)}
        return result


def parse_manifest(path: Path, variables: Mapping[str, str]) -> Manifest:
    """Parse ``path`` (a package.xml), evaluating conditions against ``variables``."""
    from lxml import (
        etree,  # imported here: 20 ms that commands without manifests should not pay
    )

    try:
        root = etree.parse(str(path), etree.XMLParser(remove_comments=True)).getroot()
    except etree.XMLSyntaxError as error:
        line = error.position[0] if error.position else None
        raise ManifestError(str(path), f"malformed XML: {error.msg}; fix the XML syntax", line) from None
    except OSError as error:
        raise ManifestError(str(path), f"cannot be read: {error.strerror or error}") from None
    return _ManifestReader(path, root, variables).read()


class _ManifestReader:
    def __init__(self, path: Path, root, variables: Mapping[str, str]):
        self.path = path
        self.root = root
        self.variables = variables
        self.variables_read: set[str] = set()

    def error(self, message: str, element=None) -> ManifestError:
        return ManifestError(str(self.path), message, (element if element is not None else self.root).sourceline)

    def holds(self, element) -> bool:
        condition = element.get("condition")
        if condition:
            self.variables_read.update(re.findall(r"\$(\w+)", condition))
        try:
            return evaluate_condition(element.get("condition"), self.variables)
        except ConditionError as error:
            raise self.error(f"invalid condition attribute: {error}", element) from None

    def text(self, tag: str, required: bool = False) -> str:
        element = self.root.find(tag)
        if element is None or not (element.text or "").strip():
            if required:
                raise self.error(f"<package> has no <{tag}>; add <{tag}>...</{tag}>")
            return ""
        return " ".join(element.text.split())

    def people(self, tag: str) -> list[str]:
        result = []
        for element in self.root.findall(tag):
            name = " ".join((element.text or "").split())
            email = element.get("email")
            result.append(f"{name} <{email}>" if email else name)
        return result

    def read(self) -> Manifest:
        if self.root.tag != "package":
            raise self.error(f"the root element is <{self.root.tag}>, a package manifest needs <package>")
        raw_format = self.root.get("format", "1")
        if raw_format not in ("1", "2", "3"):
            raise self.error(f"unsupported package format '{raw_format}'; use format=\"2\" or \"3\"")
        fmt = int(raw_format)
        allowed = _TAGS_BY_FORMAT[fmt]
        manifest = Manifest(
            path=self.path,
            format=fmt,
            name=self.text("name", required=True),
            version=self.text("version", required=True),
            description=self.text("description"),
            maintainers=self.people("maintainer"),
            authors=self.people("author"),
            licenses=[" ".join((e.text or "").split()) for e in self.root.findall("license")],
            urls=[(e.get("type", "website"), (e.text or "").strip()) for e in self.root.findall("url")],
        )
        for element in self.root:
            tag = element.tag
            if not isinstance(tag, str) or not (tag == "depend" or tag.endswith(("_depend", "_of_group"))):
                continue
            if tag not in allowed:
                raise self.error(f"<{tag}> is not allowed in package format {fmt}", element)
            name = (element.text or "").strip()
            if not name:
                raise self.error(f"<{tag}> is empty; it must name a package", element)
            if not self.holds(element):
                continue
            if tag == "group_depend":
                manifest.group_depends.append(name)
            elif tag == "member_of_group":
                manifest.member_of_groups.append(name)
            else:
                versions = tuple((a, element.get(a)) for a in VERSION_ATTRIBUTES if element.get(a) is not None)
                manifest.dependencies.append(Dependency(name, tag, versions, element.get("condition")))
        manifest.build_type = self._build_type()
        manifest.condition_variables = sorted(self.variables_read)
        return manifest

    def _build_type(self) -> str:
        export = self.root.find("export")
        if export is None:
            return "catkin"
        types = [e for e in export.findall("build_type") if self.holds(e)]
        if len(types) > 1:
            raise self.error("more than one <build_type> applies; keep one or add exclusive conditions", types[1])
        return (types[0].text or "").strip() if types else "catkin"
