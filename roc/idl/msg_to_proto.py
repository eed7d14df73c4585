""".msg -> .proto: ROS 2's own parser (rosidl_adapter) turned into proto3 files."""

from __future__ import annotations

import tempfile
from pathlib import Path

from roc.errors import RocError
from roc.idl import naming, protoc
from roc.idl.config import Config

SCALARS = {
    "bool": "bool", "byte": "uint32", "char": "uint32", "int8": "int32", "int16": "int32", "int32": "int32",
    "int64": "int64", "uint8": "uint32", "uint16": "uint32", "uint32": "uint32", "uint64": "uint64",
    "float32": "float", "float64": "double", "string": "string", "wstring": "string",
}
WELL_KNOWN = {
    "builtin_interfaces/Time": ("google.protobuf.Timestamp", "google/protobuf/timestamp.proto"),
    "builtin_interfaces/Duration": ("google.protobuf.Duration", "google/protobuf/duration.proto"),
}
INTEGERS = {"byte", "char", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64"}
# ROS types that come back unchanged from their protobuf type (others are widened).
EXACT = {"bool", "int32", "int64", "uint32", "uint64", "float32", "float64", "string"}
INT32 = range(-(2**31), 2**31)


def package_of(path: Path, package: str | None) -> str:
    if package:
        return package
    if path.parent.name == "msg":
        return path.parent.parent.name
    raise RocError(f"{path}: cannot tell its ROS package (not in <pkg>/msg/): pass --package NAME")


def parse(path: Path, package: str):
    from rosidl_adapter.parser import parse_message_string

    try:
        return parse_message_string(package, path.stem, path.read_text())
    except OSError as error:
        raise RocError(f"{path}: cannot read: {error.strerror}") from None
    except Exception as error:  # the ROS parser raises many kinds
        raise RocError(f"{path}: not a valid ROS 2 message: {error}") from None


def enum_groups(constants: list) -> tuple[dict[str, list], list]:
    """Integer constants fitting int32 grouped by the longest word prefix (``A_B`` of ``A_B_C``) they share
    with another one; groups of two or more become enums, the rest stay constants."""
    integers = [c for c in constants if c.type in INTEGERS and c.value in INT32]
    prefixes = [["_".join(c.name.split("_")[:k]) for k in range(1, c.name.count("_") + 1)] for c in integers]
    counts: dict[str, int] = {}
    for names in prefixes:
        for prefix in names:
            counts[prefix] = counts.get(prefix, 0) + 1
    groups: dict[str, list] = {}
    for const, names in zip(integers, prefixes):
        shared = [p for p in names if counts[p] > 1]
        if shared:
            groups.setdefault(shared[-1], []).append(const)
    groups = {prefix: members for prefix, members in groups.items() if len(members) > 1}
    grouped = {id(c) for members in groups.values() for c in members}
    return groups, [c for c in constants if id(c) not in grouped]


def proto_text(spec, source: str, config: Config) -> tuple[str, set[str]]:
    """The proto3 file of one message, and the files it imports."""
    package = spec.base_type.pkg_name
    name = spec.msg_name
    imports: set[str] = set()
    groups, others = enum_groups(spec.constants)
    body: list[str] = []
    for prefix, members in groups.items():
        enum = naming.camel(prefix.lower())
        enum = f"{enum}Enum" if enum == name else enum
        body.append(f"  enum {enum} {{")
        if len({c.value for c in members}) < len(members):
            body.append("    option allow_alias = true;")
        if all(c.value != 0 for c in members):
            body.append(f"    {prefix}_UNSPECIFIED = 0;  // {naming.ADDED_MARK}")
        members = sorted(members, key=lambda c: c.value != 0)  # proto3: the first value is zero
        body += [f"    {c.name} = {c.value};" for c in members]
        body.append("  }")
    for number, field in enumerate(spec.fields, 1):
        ros = field.type
        base = f"{ros.pkg_name}/{ros.type}" if ros.pkg_name else ros.type
        key = f"{package}/{name}.{field.name}"
        repeated = ros.is_array
        if key in config.fields:
            proto = config.fields[key]
        elif base in config.types:
            proto = config.types[base]
        elif ros.is_array and base in ("uint8", "byte"):
            proto, repeated = "bytes", False
        elif base in WELL_KNOWN:
            proto, file = WELL_KNOWN[base]
            imports.add(file)
        elif ros.pkg_name:
            proto = f".{config.packages.get(ros.pkg_name, ros.pkg_name)}.{ros.type}"
            imports.add(f"{ros.pkg_name}/{ros.type}.proto")
        else:
            proto = SCALARS[ros.type]
        notes = []
        exact = ros.type in EXACT or (proto == "bytes" and not ros.array_size and ros.type == "uint8")
        if ros.array_size or ros.string_upper_bound or (not ros.pkg_name and not exact):
            notes.append(f"ROS: {ros}")
        if field.default_value is not None:
            notes.append(f"default: {field.default_value}")
        comment = f"  // {', '.join(notes)}" if notes else ""
        body.append(f"  {'repeated ' if repeated else ''}{proto} {field.name} = {number};{comment}")
    lines = [f"// Generated by roc idl protobuf from {source}", 'syntax = "proto3";', "",
             f"package {config.packages.get(package, package)};", ""]
    lines += [f'import "{file}";' for file in sorted(imports)] + ([""] if imports else [])
    lines += [f"// {naming.CONSTANT_MARK}{c}" for c in others]
    lines += [f"message {name} {{", *body, "}"]
    return "\n".join(lines) + "\n", imports


def convert(paths: list[Path], package: str | None, config: Config, checked_against: list[Path]) -> dict[str, str]:
    """``pkg/Name.proto`` -> text for every .msg of ``paths``; each checked with protoc."""
    outputs: dict[str, str] = {}
    imports: set[str] = set()
    for path in paths:
        spec = parse(path, package_of(path, package))
        text, used = proto_text(spec, f"{spec.base_type.pkg_name}/msg/{path.name}", config)
        outputs[f"{spec.base_type.pkg_name}/{spec.msg_name}.proto"] = text
        imports |= used
    verify(outputs, imports, checked_against)
    return outputs


def verify(outputs: dict[str, str], imports: set[str], roots: list[Path]) -> None:
    """Compile the outputs with protoc; imports found nowhere get an empty stand-in message."""
    with tempfile.TemporaryDirectory(prefix="roc-idl-") as temporary:
        top = Path(temporary)
        for relative, text in outputs.items():
            (top / relative).parent.mkdir(parents=True, exist_ok=True)
            (top / relative).write_text(text)
        for file in imports:
            if file.startswith("google/") or file in outputs or any((r / file).is_file() for r in roots):
                continue
            package, _, type_name = file[:-6].rpartition("/")
            (top / file).parent.mkdir(parents=True, exist_ok=True)
            (top / file).write_text(f'syntax = "proto3";\npackage {package};\nmessage {type_name} {{}}\n')
        protoc.check(top, sorted(outputs), [r for r in roots if r.is_dir()])
