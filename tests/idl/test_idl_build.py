"""The .msg files roc idl protobuf writes from the corpus (with --ros-package) build with roc work build
(rosidl), and a protobuf object converted to the built ROS message and back is equal."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.build import in_sourced_shell, roc
from helpers.idl import DATA

CORPUS = ["example/robot.proto", "example/common/geometry.proto", "example/well_known.proto",
          "example/legacy.proto", "example/enums_only.proto"]

CHECK = '''
import sys
from google.protobuf import descriptor_pool, message_factory, timestamp_pb2
from roc.idl import protoc
from roc.idl.runtime import to_proto, to_ros
from pathlib import Path

data = Path(sys.argv[1])
pool = descriptor_pool.DescriptorPool()
for file in protoc.descriptor_set([data / f for f in sys.argv[2:]], [data]).file:
    pool.Add(file)
cls = lambda name: message_factory.GetMessageClass(pool.FindMessageTypeByName(name))

from example_robot_msgs.msg import Robot
from example_wkt_msgs.msg import Everything
from example_legacy_msgs.msg import Settings

robot = cls("example.robot.Robot")(name="r2", status=2, level=1000, serialNumber=77, battery=5, payload=b"\\x00\\xff",
                                   blobs=[b"ab", b""], unit=1, s32=-5, sf64=-6, f32=7, u64=2**64 - 1, ratio=0.25,
                                   enabled=True)
robot.joints.add(name="j1", position=0.5).limits.upper = 1.5
robot.joints_by_name["elbow"].position = 2.0
robot.gains[3] = 0.75
robot.point.x = 9.0
robot.stamp.seconds, robot.stamp.nanos = 10, 20
robot.uptime.seconds = 30
robot.path.add(y=1.0)
ros = to_ros(robot, Robot)
assert ros.target_case == Robot.TARGET_POINT and ros.point.x == 9.0, ros
assert ros.joints_by_name[0].key == "elbow" and ros.stamp.sec == 10 and ros.serial_number == 77
assert list(ros.blobs[0].data) == [97, 98] and ros.STATUS_FAULT == 2
back = to_proto(ros, type(robot))
assert back == robot, (back, robot)
robot.frame_id = "map"  # the other oneof member
ros = to_ros(robot, Robot)
assert ros.target_case == Robot.TARGET_FRAME_ID and to_proto(ros, type(robot)) == robot

every = cls("example.wkt.Everything")()
every.any.type_url, every.any.value = "type.googleapis.com/x", b"\\x01"
every.duration.seconds = 3
every.empty.SetInParent()
every.mask.paths.extend(["a", "b.c"])
every.struct_value.update({"k": 1.0, "s": "v"})
every.value.string_value = "text"
every.list.values.add().number_value = 2.0
every.time.seconds = 4
every.d.value, every.f.value, every.i64.value, every.u64.value = 1.5, 2.5, -3, 4
every.i32.value, every.u32.value, every.b.value, every.s.value, every.bytes_value.value = -5, 6, True, "s", b"z"
every.times.add(seconds=1)
every.blobs.add(value=b"q")
every.attributes["x"].bool_value = True
ros = to_ros(every, Everything)
assert ros.mask == ["a", "b.c"] and ros.i64 == -3 and ros.any.type_url.endswith("/x")
assert to_proto(ros, type(every)) == every

settings = to_ros(cls("example.legacy.Settings")(id=3), Settings)
assert settings.count == -7 and settings.label == 'say "hi"' and settings.mode == 1  # proto2 defaults
print("converted")
'''


@pytest.mark.slow
def test_generated_packages_build_and_convert_both_ways(tmp_path: Path):
    src = tmp_path / "ws" / "src"
    files = [str(DATA / f) for f in CORPUS]
    result = roc("idl", "protobuf", "--ros-package", "-I", str(DATA), "-o", str(src), *files, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (src / "example_robot_msgs" / "package.xml").is_file()
    build = roc("work", "build", cwd=tmp_path / "ws", timeout=900)
    assert build.returncode == 0, build.stdout + build.stderr
    (tmp_path / "check.py").write_text(CHECK)
    run = in_sourced_shell(tmp_path / "ws", f"python {tmp_path / 'check.py'} {DATA} {' '.join(CORPUS)}")
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.strip() == "converted"
