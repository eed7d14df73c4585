"""The transform maths of roc frame (roc.frames.transform) and roc frame convert, against known values."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy
import pytest
from helpers.fixture_workspaces import run_roc_inprocess, tool_environment

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


def test_pictures_without_graphviz_are_one_error_before_any_listening(tmp_path: Path, monkeypatch) -> None:
    """No dot and no graphviz-pure on PATH nor next to Python: one line, nothing written; graphviz-pure
    alone draws no PDF."""
    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))
    env = tool_environment(PATH=str(tmp_path))
    drawn = run_roc_inprocess(["frame", "tree", "--output", "tf.png"], cwd=tmp_path, env=env)
    assert (drawn.returncode, drawn.stderr) == (1, "roc: error: --output tf.png: Graphviz's 'dot' program is not "
                                                   "installed (apt install graphviz; or pip install graphviz-pure, "
                                                   "which draws .svg and .png); or write a .dot file\n")
    assert not (tmp_path / "tf.png").exists()
    (tmp_path / "graphviz-pure").symlink_to(Path(sys.prefix, "bin", "graphviz-pure"))
    assert run_roc_inprocess(["frame", "tree", "--output", "tf.pdf"], cwd=tmp_path, env=env).returncode == 1


def _tree():
    from roc.frames.buffer import Buffer

    buffer = Buffer()
    second = 1_000_000_000
    buffer.add("map", "odom", 0, Transform((1, 0, 0)), static=True)
    buffer.add("/odom", "base_link", 10 * second, Transform((0, 0, 0)), static=False)
    buffer.add("odom", "base_link", 12 * second, Transform((2, 0, 0), Transform.from_euler((0, 0, 0), (0, 0, math.pi / 2)).rotation), static=False)
    buffer.add("base_link", "laser", 0, Transform((0, 1, 0)), static=True)
    buffer.add("camera", "lens", 0, Transform((0, 0, 1)), static=True)
    return buffer, second


def test_buffer_lookups_equal_transforms_composed_by_hand() -> None:
    buffer, second = _tree()
    latest, stamp = buffer.lookup("map", "laser")
    assert stamp == 12 * second
    by_hand = Transform((1, 0, 0)) @ buffer.links["base_link"].transforms[-1] @ Transform((0, 1, 0))
    assert close(latest.matrix(), by_hand.matrix()) and close(latest.translation, (2, 0, 0))
    inverse, _ = buffer.lookup("laser", "map")
    assert close(inverse.matrix(), by_hand.inverse().matrix())
    sibling, _ = buffer.lookup("laser", "odom")  # up to base_link's parent and down again
    assert close(sibling.matrix(), (buffer.links["base_link"].transforms[-1] @ Transform((0, 1, 0))).inverse().matrix())


def test_buffer_interpolates_between_stamps() -> None:
    buffer, second = _tree()
    half, stamp = buffer.lookup("odom", "base_link", 11 * second)
    assert stamp == 11 * second
    assert close(half.translation, (1, 0, 0)) and half.euler()[2] == pytest.approx(math.pi / 4)
    static_only, stamp = buffer.lookup("camera", "lens")
    assert stamp == 0 and close(static_only.translation, (0, 0, 1))


@pytest.mark.parametrize("target, source, stamp, error", [
    ("map", "nowhere", 0, "frame 'nowhere' (source) does not exist (frames: base_link, camera, laser, lens, map, odom)"),
    ("map", "lens", 0, "map and lens are not connected (trees: camera->lens; map->odom->base_link->laser)"),
    ("map", "base_link", 13, "lookup would need extrapolation into the future: asked for 13.000, the latest "
                             "transform of base_link is at 12.000"),
    ("map", "base_link", 9, "lookup would need extrapolation into the past: asked for 9.000, the oldest "
                            "transform of base_link kept is at 10.000"),
])
def test_buffer_errors(target: str, source: str, stamp: int, error: str) -> None:
    from roc.frames.buffer import TransformUnavailable

    buffer, second = _tree()
    with pytest.raises(TransformUnavailable) as raised:
        buffer.lookup(target, source, stamp * second)
    assert str(raised.value) == error
