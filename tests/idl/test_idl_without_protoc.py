"""roc idl without grpcio-tools (roc's idl extra, not a dependency): one line saying how to install it."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from helpers.build import BIN, ros_env


def test_roc_idl_without_grpcio_tools_says_in_one_line_how_to_install_it(tmp_path: Path):
    hidden = tmp_path / "hidden" / "grpc_tools"  # first on sys.path: grpc_tools does not import
    hidden.mkdir(parents=True)
    (hidden / "__init__.py").write_text("raise ImportError('grpcio-tools is not installed')\n")
    (tmp_path / "robot.proto").write_text('syntax = "proto3";\npackage robot;\nmessage Pose { double x = 1; }\n')
    env = {**ros_env(), "PYTHONPATH": os.pathsep.join(filter(None, [str(hidden.parent), ros_env().get("PYTHONPATH")]))}
    result = subprocess.run([str(BIN / "roc"), "idl", "protobuf", "robot.proto"], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 1, result.stderr
    assert result.stdout == ""
    assert result.stderr.count("\n") == 1, result.stderr
    assert result.stderr.startswith("roc: error: protoc is not installed: ")
    assert result.stderr.rstrip().endswith("-m pip install grpcio-tools (pipx: pipx inject roc-ros2 grpcio-tools)")
