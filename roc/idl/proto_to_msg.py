""".proto -> .msg: protoc's descriptors (never a hand-written scanner) turned into ROS 2 messages."""

from __future__ import annotations

import codecs
import math
from dataclasses import dataclass, field
from typing import Any

from roc.errors import RocError
from roc.idl import naming
from roc.idl.config import Config

SCALARS = {
    1: "float64", 2: "float32", 3: "int64", 4: "uint64", 5: "int32", 6: "uint64", 7: "uint32", 8: "bool",
    9: "string", 12: "uint8[]", 13: "uint32", 15: "int32", 16: "int64", 17: "int32", 18: "int64",
}  # FieldDescriptorProto.Type numbers (14 enum, 11 message, 10 group)
TYPE_GROUP, TYPE_MESSAGE, TYPE_BYTES, TYPE_ENUM = 10, 11, 12, 14
LABEL_REPEATED = 3
WELL_KNOWN = {
    "google.protobuf.Timestamp": "builtin_interfaces/Time",
    "google.protobuf.Duration": "builtin_interfaces/Duration",
    "google.protobuf.DoubleValue": "float64", "google.protobuf.FloatValue": "float32",
    "google.protobuf.Int64Value": "int64", "google.protobuf.UInt64Value": "uint64",
    "google.protobuf.Int32Value": "int32", "google.protobuf.UInt32Value": "uint32",
    "google.protobuf.BoolValue": "bool", "google.protobuf.StringValue": "string",
    "google.protobuf.BytesValue": "uint8[]",
    "google.protobuf.Struct": "string", "google.protobuf.Value": "string", "google.protobuf.ListValue": "string",
    "google.protobuf.FieldMask": "string[]",
    "google.protobuf.Any": "Any", "google.protobuf.Empty": "Empty",
}
# Messages generated in the output package when a field needs them.
HELPERS = {
    "Bytes": "# One element of a repeated bytes field.\nuint8[] data\n",
    "Any": "# google.protobuf.Any\nstring type_url\nuint8[] value\n",
    "Empty": "# google.protobuf.Empty\n",
}


@dataclass
class Definition:
    """A message or enum of the descriptor set."""

    full: str  # a.b.Robot.Status
    proto: Any  # DescriptorProto | EnumDescriptorProto
    file: Any  # FileDescriptorProto
    path: tuple[int, ...]  # source-info path
    is_enum: bool
    package: str = ""  # ROS package
    name: str = ""  # ROS message name
    parent: str | None = None  # enclosing message (full name)


@dataclass
class Converter:
    files: Any  # FileDescriptorSet
    config: Config
    package: str | None
    definitions: dict[str, Definition] = field(default_factory=dict)
    lines: dict[str, dict[tuple[int, ...], Any]] = field(default_factory=dict)  # SourceCodeInfo.Location
    notes: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        for file in self.files.file:
            self.lines[file.name] = {tuple(loc.path): loc for loc in file.source_code_info.location}
            for i, message in enumerate(file.message_type):
                self._add(file, message, (4, i), file.package, None)
            for i, enum in enumerate(file.enum_type):
                self._add_enum(file, enum, (5, i), file.package, None)

    # ---- index ---------------------------------------------------------------------------
    def _add(self, file, message, path, scope: str, parent: str | None) -> None:
        full = f"{scope}.{message.name}" if scope else message.name
        self.definitions[full] = Definition(full, message, file, path, False, parent=parent)
        for j, nested in enumerate(message.nested_type):
            self._add(file, nested, (*path, 3, j), full, full)
        for j, enum in enumerate(message.enum_type):
            self._add_enum(file, enum, (*path, 4, j), full, full)

    def _add_enum(self, file, enum, path, scope: str, parent: str | None) -> None:
        full = f"{scope}.{enum.name}" if scope else enum.name
        self.definitions[full] = Definition(full, enum, file, path, True, parent=parent)

    def where(self, definition: Definition, path: tuple[int, ...] | None = None) -> str:
        location = self.lines[definition.file.name].get(path or definition.path)
        return f"{definition.file.name}:{location.span[0] + 1}" if location else definition.file.name

    def comment(self, definition: Definition, path: tuple[int, ...], trailing: bool = False) -> str:
        location = self.lines[definition.file.name].get(path)
        if location is None:
            return ""
        return (location.trailing_comments if trailing else location.leading_comments).strip()

    def name_all(self) -> None:
        """Give every definition its ROS package and flattened name; collisions are errors."""
        taken: dict[tuple[str, str], Definition] = {}
        for definition in self.definitions.values():
            file = definition.file
            if file.package.startswith("google.protobuf"):
                continue
            if file.package in self.config.packages:
                definition.package = self.config.packages[file.package]
            elif file.package:
                definition.package = naming.ros_package(file.package)
            elif self.package:
                definition.package = self.package
            else:
                raise RocError(f"{file.name}: no 'package' statement: pass --package NAME")
            relative = definition.full[len(file.package) + 1:] if file.package else definition.full
            definition.name = self.config.renames.get(definition.full) or "".join(
                naming.camel(part) for part in relative.split("."))
            if definition.parent and definition.is_enum:
                continue  # nested enums become constants of their message
            key = (definition.package, definition.name)
            other = taken.setdefault(key, definition)
            if other is not definition:
                raise RocError(f"{self.where(definition)}: '{definition.full}' and '{other.full}' both become "
                               f"{key[0]}/{key[1]}: rename one with --config (renames:)")

    # ---- fields --------------------------------------------------------------------------
    def ros_ref(self, full: str, package: str, helpers: set[str]) -> str:
        if full in self.config.types:
            return self.config.types[full]
        if full in WELL_KNOWN:
            ros = WELL_KNOWN[full]
            if ros in HELPERS:
                helpers.add(ros)
            return ros
        target = self.definitions[full]
        if target.is_enum:
            return enum_type(target.proto)
        return target.name if target.package == package else f"{target.package}/{target.name}"

    def field_type(self, owner: Definition, index: int, helpers: set[str]) -> str:
        proto = owner.proto.field[index]
        retyped = self.config.fields.get(f"{owner.full}.{proto.name}")
        if retyped:
            self.notes.append(f"{owner.full}.{proto.name}: retyped to {retyped} (--config)")
            return retyped
        if proto.type in (TYPE_MESSAGE, TYPE_GROUP, TYPE_ENUM):
            base = self.ros_ref(proto.type_name.lstrip("."), owner.package, helpers)
        else:
            base = SCALARS[proto.type]
        if proto.label != LABEL_REPEATED:
            return base
        if base == "uint8[]":
            helpers.add("Bytes")
            return "Bytes[]"
        if base.endswith("]"):
            raise RocError(f"{self.where(owner, (*owner.path, 2, index))}: repeated {proto.type_name.lstrip('.')} "
                           "has no ROS type: retype it with --config (fields:)")
        return f"{base}[]"

    def default(self, owner: Definition, proto) -> str:
        value = proto.default_value
        if proto.type == 8:
            return value
        if proto.type in (1, 2):
            return "nan" if math.isnan(float(value)) else value
        if proto.type == 9:
            return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if proto.type == TYPE_BYTES:
            return "[" + ", ".join(str(b) for b in codecs.escape_decode(value.encode())[0]) + "]"
        if proto.type == TYPE_ENUM:
            enum = self.definitions[proto.type_name.lstrip(".")].proto
            return str(next(v.number for v in enum.value if v.name == value))
        return value

    # ---- messages ------------------------------------------------------------------------
    def constants(self, definition: Definition) -> list[str]:
        """Constant lines of an enum (values marked as added by msg -> proto are skipped)."""
        lines = []
        kind = enum_type(definition.proto)
        for k, value in enumerate(definition.proto.value):
            if self.comment(definition, (*definition.path, 2, k), trailing=True) == naming.ADDED_MARK:
                continue
            lines.append(f"{kind} {naming.constant(value.name)}={value.number}")
        return lines

    def message_text(self, definition: Definition, helpers: set[str]) -> str:
        message = definition.proto
        out = [f"# Generated by roc idl protobuf from {definition.file.name} ({definition.full})"]
        header = self.comment(definition, definition.path)
        consts: list[str] = []
        for line in header.splitlines():
            if line.strip().startswith(naming.CONSTANT_MARK):
                consts.append(line.strip()[len(naming.CONSTANT_MARK):])
            else:
                out.append(f"# {line.rstrip()}".rstrip())
        for enum in message.enum_type:
            consts += self.constants(self.definitions[f"{definition.full}.{enum.name}"])
        oneofs = {}
        for o, oneof in enumerate(message.oneof_decl):
            members = [f for f in message.field if f.HasField("oneof_index") and f.oneof_index == o
                       and not f.proto3_optional]
            if members:
                oneofs[o] = naming.snake(oneof.name) + "_case"
                consts.append(f"uint8 {naming.constant(oneof.name + '_not_set')}=0")
                consts += [f"uint8 {naming.constant(oneof.name + '_' + f.name)}={n}" for n, f in enumerate(members, 1)]
        out += consts
        names: dict[str, str] = {}
        for i, proto in enumerate(message.field):
            if proto.HasField("oneof_index") and oneofs.get(proto.oneof_index):
                out.append(f"uint8 {oneofs.pop(proto.oneof_index)}")
            name = naming.snake(proto.name)
            if names.setdefault(name, proto.name) != proto.name:
                raise RocError(f"{self.where(definition, (*definition.path, 2, i))}: fields '{names[name]}' and "
                               f"'{proto.name}' both become '{name}'")
            for line in self.comment(definition, (*definition.path, 2, i)).splitlines():
                out.append(f"# {line.rstrip()}".rstrip())
            line = f"{self.field_type(definition, i, helpers)} {name}"
            if proto.HasField("default_value") and f"{definition.full}.{proto.name}" not in self.config.fields:
                value = self.default(definition, proto)
                if proto.type in (1, 2) and not math.isfinite(float(value)):
                    # the ROS parsers accept nan/inf, but rosidl's C generator emits code that does not compile
                    out.append(f"# default: {value} (not finite: rosidl cannot build it)")
                else:
                    line += f" {value}"
            out.append(line)
        return "\n".join(out) + "\n"

    def check_cycles(self, roots: list[Definition]) -> None:
        """ROS 2 cannot build recursive messages: a cycle is an error naming it."""
        state: dict[str, int] = {}

        def visit(definition: Definition, trail: list[str]) -> None:
            state[definition.full] = 1
            for i, proto in enumerate(definition.proto.field):
                target = proto.type_name.lstrip(".")
                if (proto.type not in (TYPE_MESSAGE, TYPE_GROUP) or target in WELL_KNOWN
                        or target in self.config.types or f"{definition.full}.{proto.name}" in self.config.fields):
                    continue
                step = f"{definition.full}.{proto.name}"
                if state.get(target) == 1:
                    cycle = trail[[t.rsplit(".", 1)[0] for t in trail].index(target):] if any(
                        t.rsplit(".", 1)[0] == target for t in trail) else []
                    chain = " -> ".join([*cycle, step, target])
                    raise RocError(f"{self.where(definition, (*definition.path, 2, i))}: recursive type {chain}: "
                                   "ROS 2 cannot build it; retype a field with --config (fields:)")
                if target not in state:
                    visit(self.definitions[target], [*trail, step])
            state[definition.full] = 2

        for definition in roots:
            if definition.full not in state:
                visit(definition, [])


def enum_type(enum) -> str:
    return "uint8" if all(0 <= v.number <= 255 for v in enum.value) else "int32"


def convert(files: object, targets: list[str], config: Config, package: str | None) -> tuple[dict[str, str], list[str]]:
    """The .msg files (``pkg/msg/Name.msg`` -> text) of the proto files ``targets`` (names in ``files``)."""
    converter = Converter(files, config, package)
    converter.name_all()
    chosen = [d for d in converter.definitions.values() if d.file.name in targets]
    converter.check_cycles([d for d in chosen if not d.is_enum])
    outputs: dict[str, str] = {}
    helpers: dict[str, Definition] = {}  # pkg/msg/Helper.msg -> the first definition using it
    for definition in chosen:
        if definition.is_enum and definition.parent:
            continue
        used: set[str] = set()
        if definition.is_enum:
            text = (f"# Generated by roc idl protobuf from {definition.file.name} (enum {definition.full})\n"
                    + "".join(f"{line}\n" for line in converter.constants(definition)))
        else:
            text = converter.message_text(definition, used)
        outputs[f"{definition.package}/msg/{definition.name}.msg"] = text
        for helper in used:
            helpers.setdefault(f"{definition.package}/msg/{helper}.msg", definition)
    for key, definition in helpers.items():
        if key in outputs:
            raise RocError(f"{converter.where(definition)}: the message roc generates for {key.rsplit('/')[-1][:-4]} "
                           f"collides with {key}: rename that one with --config (renames:)")
        outputs[key] = HELPERS[key.rsplit("/")[-1][:-4]]
    verify(outputs)
    return outputs, converter.notes


def verify(outputs: dict[str, str]) -> None:
    """Every .msg written must pass ROS 2's own parser."""
    from rosidl_adapter.parser import parse_message_string

    for relative, text in outputs.items():
        package, _, file = relative.split("/")
        try:
            parse_message_string(package, file[:-4], text)
        except Exception as error:  # the ROS parser raises many kinds
            raise RocError(f"{relative}: the generated message does not pass the ROS 2 parser: {error}") from None
