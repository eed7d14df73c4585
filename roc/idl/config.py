"""``roc idl protobuf --config FILE``: type mappings and renames (YAML)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from roc.errors import RocError

KEYS = {
    "types": "type full name -> type in the other IDL (e.g. example.Blob: string, geometry_msgs/Point: my.Point)",
    "fields": "one field retyped: <message full name>.<field> -> type in the other IDL",
    "renames": "proto message or enum full name -> ROS message name",
    "packages": "package in the input IDL -> package in the output IDL",
}


@dataclass
class Config:
    types: dict[str, str] = field(default_factory=dict)
    fields: dict[str, str] = field(default_factory=dict)
    renames: dict[str, str] = field(default_factory=dict)
    packages: dict[str, str] = field(default_factory=dict)


def load(path: Path | None) -> Config:
    if path is None:
        return Config()
    import yaml

    try:
        data = yaml.safe_load(path.read_text()) or {}
    except OSError as error:
        raise RocError(f"{path}: cannot read: {error.strerror}") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark else str(path)
        raise RocError(f"{where}: not valid YAML") from None
    if not isinstance(data, dict):
        raise RocError(f"{path}: expected a mapping with the keys {', '.join(KEYS)}")
    config = Config()
    for key, value in data.items():
        if key not in KEYS:
            raise RocError(f"{path}: unknown key '{key}' (known keys: {', '.join(KEYS)})")
        if not isinstance(value, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in value.items()):
            raise RocError(f"{path}: '{key}' must map names to names ({KEYS[key]})")
        setattr(config, key, dict(value))
    return config
