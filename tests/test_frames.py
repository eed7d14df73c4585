"""The transform maths of roc frame (roc.frames.transform) and roc frame convert, against known values."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy
import pytest
from fixture_workspaces import run_roc_inprocess, tool_environment

from roc.frames.transform import Transform, interpolate

H = math.sqrt(0.5)


def close(a, b) -> bool:
    return numpy.allclose(numpy.asarray(a, dtype=float), numpy.asarray(b, dtype=float), atol=1e-9)


def test_euler_quaternion_matrix_and_axis_angle_agree() -> None:
    yaw = Transform.from_euler((0, 0, 0), (0, 0, math.pi / 2))
    assert close(yaw.rotation, (0, 0, H, H))
    assert close(yaw.rotation_matrix(), [[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    axis, angle = yaw.axis_angle()
    assert close(axis, (0, 0, 1)) and angle == pytest.approx(math.pi / 2)
    assert close(Transform.from_matrix(yaw.rotation_matrix()).rotation, yaw.rotation)
    assert close(Transform.from_axis_angle((0, 0, 2), math.pi / 2).rotation, yaw.rotation)
    # rotating axes: x then the new y equals static y then x
    assert close(Transform.from_euler((0, 0, 0), (0.3, 0.2, 0), "rxyz").rotation_matrix(),
                 Transform.from_euler((0, 0, 0), (0.2, 0.3, 0), "syxz").rotation_matrix())


def test_gimbal_lock_keeps_the_rotation() -> None:
    locked = Transform.from_euler((0, 0, 0), (0.3, math.pi / 2, 0.2))
    roll, pitch, yaw = locked.euler()
    assert pitch == pytest.approx(math.pi / 2)
    assert close(Transform.from_euler((0, 0, 0), (roll, pitch, yaw)).rotation_matrix(), locked.rotation_matrix())


def test_composition_and_inverse() -> None:
    parent_child = Transform.from_euler((1, 0, 0), (0, 0, math.pi / 2))
    child_grandchild = Transform((1, 0, 0))
    composed = parent_child @ child_grandchild
    assert close(composed.translation, (1, 1, 0)) and close(composed.rotation, parent_child.rotation)
    identity = composed @ composed.inverse()
    assert close(identity.translation, (0, 0, 0)) and close(identity.matrix(), numpy.eye(4))
    assert close(composed.matrix(), parent_child.matrix() @ child_grandchild.matrix())


def test_interpolation_is_linear_and_slerp_the_short_way() -> None:
    before = Transform((0, 0, 0), Transform.from_euler((0, 0, 0), (0, 0, 0)).rotation)
    after = Transform((2, 0, 0), Transform.from_euler((0, 0, 0), (0, 0, math.pi / 2)).rotation)
    half = interpolate(before, after, 0.5)
    assert close(half.translation, (1, 0, 0)) and half.euler()[2] == pytest.approx(math.pi / 4)
    across = interpolate(Transform.from_euler((0, 0, 0), (0, 0, math.radians(170))),
                         Transform.from_euler((0, 0, 0), (0, 0, math.radians(-170))), 0.5)
    assert abs(across.euler()[2]) == pytest.approx(math.pi)


def _convert(*args: str):
    return run_roc_inprocess(["frame", "convert", *args], Path.cwd(), tool_environment())


def test_convert_prints_as_tf2_echo_and_json() -> None:
    result = _convert("-e", "0", "0", "90", "--degrees")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[:4] == [
        "- Translation: [0.000, 0.000, 0.000]", "- Rotation: in Quaternion (xyzw) [0.000, 0.000, 0.707, 0.707]",
        "- Rotation: in RPY (radian) [0.000, 0.000, 1.571]", "- Rotation: in RPY (degree) [0.000, 0.000, 90.000]"]
    composed = json.loads(_convert("-t", "1 0 0 0 0 90", "-t", "1 0 0 0 0 0", "--degrees", "--inverse",
                                   "--format", "json").stdout)
    assert close(composed["translation"], (-1, 1, 0)) and composed["rpy_degrees"][2] == pytest.approx(-90)


@pytest.mark.parametrize("args, error", [
    (["-q", "0", "0", "0", "0"], "--quaternion: a quaternion of length 0 is no rotation"),
    (["-m", "1", "0", "0", "0", "2", "0", "0", "0", "1"], "--matrix: not a rotation matrix"),
    (["-a", "0", "0", "0", "1"], "--axis-angle: the axis must not be 0 0 0"),
    (["-t", "1 2 3 4 5"], "--transform '1 2 3 4 5': expected 6 numbers (x y z roll pitch yaw) or 7"),
])
def test_convert_errors(args: list[str], error: str) -> None:
    result = _convert(*args)
    assert result.returncode == 2 and result.stderr.startswith(f"roc: error: {error}")
