"""A rigid transform (translation and unit quaternion, ROS's x, y, z, w order) and the conversions
between rotation representations, on transforms3d (which orders quaternions w, x, y, z)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy
from transforms3d import euler, quaternions

AXES = ("sxyz", "sxzy", "syxz", "syzx", "szxy", "szyx", "rxyz", "rxzy", "ryxz", "ryzx", "rzxy", "rzyx")


def _wxyz(quaternion: tuple[float, float, float, float]) -> numpy.ndarray:
    x, y, z, w = quaternion
    return numpy.array([w, x, y, z], dtype=float)


def vector(values: Iterable[float]) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in values)
    return (x, y, z)


def _xyzw(wxyz: numpy.ndarray) -> tuple[float, float, float, float]:
    w, x, y, z = (float(v) for v in wxyz)
    return (x, y, z, w)


def normalized(quaternion: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """The unit quaternion (an error for a zero one: it is no rotation)."""
    norm = math.sqrt(sum(v * v for v in quaternion))
    if norm < 1e-12:
        raise ValueError("a quaternion of length 0 is no rotation")
    return tuple(v / norm for v in quaternion)  # type: ignore[return-value]


@dataclass(frozen=True)
class Transform:
    translation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)  # x, y, z, w

    @classmethod
    def from_euler(cls, translation, angles, axes: str = "sxyz") -> Transform:
        """From Euler angles in radians (``sxyz``: static axes, roll about x, pitch about y, yaw about z)."""
        return cls(tuple(translation), _xyzw(euler.euler2quat(*angles, axes)))

    @classmethod
    def from_matrix(cls, matrix, translation=(0.0, 0.0, 0.0)) -> Transform:
        return cls(tuple(translation), _xyzw(quaternions.mat2quat(numpy.asarray(matrix, dtype=float))))

    @classmethod
    def from_axis_angle(cls, axis, angle: float, translation=(0.0, 0.0, 0.0)) -> Transform:
        return cls(tuple(translation), _xyzw(quaternions.axangle2quat(axis, angle)))

    def __matmul__(self, other: Transform) -> Transform:
        """``self`` then ``other`` in ``self``'s frame: parent->child composed with child->grandchild."""
        q = _wxyz(self.rotation)
        moved = quaternions.rotate_vector(numpy.array(other.translation), q) + numpy.array(self.translation)
        return Transform(vector(moved), _xyzw(quaternions.qmult(q, _wxyz(other.rotation))))

    def inverse(self) -> Transform:
        q = quaternions.qinverse(_wxyz(self.rotation))
        moved = -quaternions.rotate_vector(numpy.array(self.translation), q)
        return Transform(vector(moved), _xyzw(q))

    def euler(self, axes: str = "sxyz") -> tuple[float, float, float]:
        return tuple(float(v) for v in euler.quat2euler(_wxyz(self.rotation), axes))  # type: ignore[return-value]

    def rotation_matrix(self) -> numpy.ndarray:
        return quaternions.quat2mat(_wxyz(self.rotation))

    def matrix(self) -> numpy.ndarray:
        """The 4x4 homogeneous matrix."""
        matrix = numpy.eye(4)
        matrix[:3, :3] = self.rotation_matrix()
        matrix[:3, 3] = self.translation
        return matrix

    def axis_angle(self) -> tuple[tuple[float, float, float], float]:
        axis, angle = quaternions.quat2axangle(_wxyz(self.rotation))
        return tuple(float(v) for v in axis), float(angle)  # type: ignore[return-value]


def interpolate(before: Transform, after: Transform, fraction: float) -> Transform:
    """Between two transforms: translation linearly, rotation along the shortest arc (slerp)."""
    q0 = _wxyz(before.rotation)
    relative = quaternions.qmult(quaternions.qinverse(q0), _wxyz(after.rotation))
    if relative[0] < 0:  # the same rotation the short way round
        relative = -relative
    axis, angle = quaternions.quat2axangle(relative)
    rotation = quaternions.qmult(q0, quaternions.axangle2quat(axis, angle * fraction))
    translation = (1 - fraction) * numpy.array(before.translation) + fraction * numpy.array(after.translation)
    return Transform(vector(translation), _xyzw(rotation))
