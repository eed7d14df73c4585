"""roc frame convert: a calculator between rotation representations (quaternion, Euler angles, rotation
matrix, axis-angle), and the composition and inverse of transforms."""

from __future__ import annotations

import argparse
import math

from roc.errors import UsageError
from roc.frames.transform import AXES, Transform, normalized, vector
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    given = parser.add_mutually_exclusive_group(required=True)
    given.add_argument("-q", "--quaternion", nargs=4, type=float, metavar=("X", "Y", "Z", "W"),
                       help="a quaternion (x, y, z, w)")
    given.add_argument("-e", "--euler", nargs=3, type=float, metavar=("A", "B", "C"),
                       help="Euler angles about --axes (default sxyz: roll, pitch, yaw about the fixed x, y, z)")
    given.add_argument("-m", "--matrix", nargs=9, type=float, metavar="M", help="a rotation matrix, row by row")
    given.add_argument("-a", "--axis-angle", nargs=4, type=float, metavar=("X", "Y", "Z", "ANGLE"),
                       help="a rotation axis and an angle about it")
    given.add_argument("-t", "--transform", action="append", metavar="'X Y Z ROLL PITCH YAW' or 'X Y Z QX QY QZ QW'",
                       help="a transform; several are composed in order (parent->child, child->grandchild, ...)")
    parser.add_argument("--inverse", action="store_true", help="print the inverse of the result")
    parser.add_argument("--axes", default="sxyz", choices=AXES,
                        help="Euler axis order: s (static) or r (rotating) then the axes (default: sxyz)")
    parser.add_argument("--degrees", action="store_true", help="angles given in degrees (default: radians)")
    parser.add_argument("--precision", type=int, default=3, metavar="N", help="decimals printed (default: 3)")
    parser.add_argument("--format", choices=("text", "json"), default="text", help="output format (default: text)")


def _parsed_transform(text: str, degrees: bool, axes: str) -> Transform:
    try:
        values = [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise UsageError(f"--transform '{text}': expected numbers") from None
    if len(values) == 6:
        angles = [math.radians(v) for v in values[3:]] if degrees else values[3:]
        return Transform.from_euler(values[:3], angles, axes)
    if len(values) == 7:
        return Transform(vector(values[:3]), _unit(values[3:], f"--transform '{text}'"))
    raise UsageError(f"--transform '{text}': expected 6 numbers (x y z roll pitch yaw) or 7 (x y z qx qy qz qw), "
                     f"got {len(values)}")


def _unit(quaternion, where: str):
    try:
        return normalized(tuple(quaternion))
    except ValueError as error:
        raise UsageError(f"{where}: {error}") from None


def given_transform(args: argparse.Namespace) -> Transform:
    angle = math.radians if args.degrees else float
    if args.quaternion:
        return Transform(rotation=_unit(args.quaternion, "--quaternion"))
    if args.euler:
        return Transform.from_euler((0, 0, 0), [angle(v) for v in args.euler], args.axes)
    if args.matrix:
        rows = [args.matrix[i:i + 3] for i in (0, 3, 6)]
        product = [[sum(rows[i][k] * rows[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
        if any(abs(product[i][j] - (i == j)) > 1e-6 for i in range(3) for j in range(3)):
            raise UsageError("--matrix: not a rotation matrix (its rows must be orthonormal)")
        return Transform.from_matrix(rows)
    if args.axis_angle:
        *axis, value = args.axis_angle
        if not any(axis):
            raise UsageError("--axis-angle: the axis must not be 0 0 0")
        return Transform.from_axis_angle(axis, angle(value))
    result = Transform()
    for text in args.transform:
        result = result @ _parsed_transform(text, args.degrees, args.axes)
    return result


def transform_data(transform: Transform, axes: str = "sxyz") -> dict:
    axis, angle = transform.axis_angle()
    rpy = transform.euler("sxyz")
    data = {"translation": list(transform.translation), "quaternion": list(transform.rotation),
            "rpy": list(rpy), "rpy_degrees": [math.degrees(v) for v in rpy],
            "axis_angle": {"axis": list(axis), "angle": angle},
            "matrix": [list(map(float, row)) for row in transform.matrix()]}
    if axes != "sxyz":
        data["euler"] = {"axes": axes, "angles": list(transform.euler(axes))}
    return data


def transform_lines(transform: Transform, precision: int = 3, axes: str = "sxyz") -> list[str]:
    """As tf2_echo prints a transform, then roc's Euler angles for other axes and the axis-angle."""
    data = transform_data(transform, axes)

    def numbers(values) -> str:
        return "[" + ", ".join(f"{0.0 if abs(v) < 0.5 * 10 ** -precision else v:.{precision}f}" for v in values) + "]"
    lines = [f"- Translation: {numbers(data['translation'])}",
             f"- Rotation: in Quaternion (xyzw) {numbers(data['quaternion'])}",
             f"- Rotation: in RPY (radian) {numbers(data['rpy'])}",
             f"- Rotation: in RPY (degree) {numbers(data['rpy_degrees'])}"]
    if "euler" in data:
        lines.append(f"- Rotation: in Euler {axes} (radian) {numbers(data['euler']['angles'])}")
    angle = data["axis_angle"]["angle"]
    lines.append(f"- Rotation: axis {numbers(data['axis_angle']['axis'])}, angle {angle:.{precision}f} rad "
                 f"({math.degrees(angle):.{precision}f} deg)")
    lines.append("- Matrix:")
    lines += ["  " + " ".join(f"{0.0 if abs(v) < 0.5 * 10 ** -precision else v:{precision + 4}.{precision}f}"
                              for v in row) for row in data["matrix"]]
    return lines


def run(args: argparse.Namespace) -> int:
    if args.precision < 0:
        raise UsageError("--precision must be 0 or more")
    transform = given_transform(args)
    if args.inverse:
        transform = transform.inverse()
    render(transform_data(transform, args.axes), args.format, transform_lines(transform, args.precision, args.axes))
    return 0
