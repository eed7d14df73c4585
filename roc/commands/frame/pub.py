"""roc frame pub: publish a transform between two frames, like static_transform_publisher: on
/tf_static (transient local) by default, on /tf at --rate; until Ctrl+C."""

from __future__ import annotations

import argparse
import math
import time

from roc.cli.options import add_discovery_arguments
from roc.errors import UsageError
from roc.frames.transform import Transform, normalized
from roc.render import print_text
from roc.ros.client import stream
from roc.ros.protocol import task_node_name
from roc.ros.types import TF_TYPE, message_class


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("parent_frame", help="the frame the transform is given in, e.g. map")
    parser.add_argument("child_frame", help="the frame it places, e.g. odom")
    for axis in ("x", "y", "z"):
        parser.add_argument(f"--{axis}", type=float, default=0.0, help=f"translation along {axis} (m)")
    for angle in ("roll", "pitch", "yaw"):
        parser.add_argument(f"--{angle}", type=float, help=f"{angle} (radians, or degrees with --degrees)")
    parser.add_argument("--degrees", action="store_true", help="--roll, --pitch and --yaw are in degrees")
    for part in ("qx", "qy", "qz", "qw"):
        parser.add_argument(f"--{part}", type=float, help="the rotation as a quaternion (instead of roll/pitch/yaw)")
    parser.add_argument("--rate", type=float, metavar="HZ",
                        help="publish on /tf this often (default: once, on /tf_static)")
    parser.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this long (default: Ctrl+C)")
    add_discovery_arguments(parser)


def given(args: argparse.Namespace) -> Transform:
    quaternion = [args.qx, args.qy, args.qz, args.qw]
    angles = [args.roll, args.pitch, args.yaw]
    if any(v is not None for v in quaternion):
        if any(v is not None for v in angles):
            raise UsageError("give the rotation as --roll/--pitch/--yaw or as --qx/--qy/--qz/--qw, not both")
        if any(v is None for v in quaternion):
            raise UsageError("a quaternion needs all of --qx --qy --qz --qw")
        try:
            return Transform((args.x, args.y, args.z), normalized(tuple(quaternion)))
        except ValueError as error:
            raise UsageError(f"--qx/--qy/--qz/--qw: {error}") from None
    values = [v or 0.0 for v in angles]
    return Transform.from_euler((args.x, args.y, args.z), [math.radians(v) for v in values] if args.degrees else values)


def message(parent: str, child: str, transform: Transform):
    from geometry_msgs.msg import TransformStamped

    stamped = TransformStamped()
    stamped.header.frame_id, stamped.child_frame_id = parent, child
    (stamped.transform.translation.x, stamped.transform.translation.y,
     stamped.transform.translation.z) = transform.translation
    r = stamped.transform.rotation
    r.x, r.y, r.z, r.w = transform.rotation
    return message_class(TF_TYPE)(transforms=[stamped])


def _stamped(tf_message):
    now = time.time_ns()
    for stamped in tf_message.transforms:
        stamped.header.stamp.sec, stamped.header.stamp.nanosec = divmod(now, 1_000_000_000)
    return tf_message


def run(args: argparse.Namespace) -> int:
    from roc.frames.listen import require_tf2_msgs
    from roc.ros.cdr import encode, serialize

    require_tf2_msgs()
    if args.rate is not None and args.rate <= 0:
        raise UsageError(f"--rate: must be above 0 Hz, got {args.rate:g}")
    if args.parent_frame.lstrip("/") == args.child_frame.lstrip("/"):
        raise UsageError("the parent and child frames must differ")
    tf_message = message(args.parent_frame, args.child_frame, given(args))
    static = args.rate is None
    params = {"topic": "/tf_static" if static else "/tf", "type": TF_TYPE, "data": encode(_stamped(tf_message)),
              "qos": {"profile": "default", "depth": 1 if static else 100,
                      **({"durability": "transient_local"} if static else {})},
              "rate": args.rate, "times": 1 if static else 0, "wait": 0, "max_wait": None,
              "keep_alive": None if static else 0.1, "node": task_node_name("frame_pub")}
    local = {} if static else {"prepare": lambda: serialize(_stamped(tf_message))}  # stamped anew each time
    deadline = time.monotonic() + args.duration if args.duration is not None else None
    where = "/tf_static" if static else f"/tf at {args.rate:g} Hz"
    for event in stream("publish", params, use_daemon=not args.no_daemon and static, heartbeats=True, **local):
        if event["event"] == "started":
            print_text(f"publishing {args.parent_frame} -> {args.child_frame} on {where}; Ctrl+C to stop\n")
        if deadline is not None and time.monotonic() >= deadline:
            break
    return 0
