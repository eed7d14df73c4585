"""roc's own evaluation of content filters against Fast DDS's: publishes a set of varied
sensor_msgs/JointState messages to a subscription filtered by the middleware for each expression,
and prints, per expression, the names of the messages Fast DDS delivered and of those
roc.ros.content_filter accepts, as JSON lines.

    python content_filter_oracle.py"""

from __future__ import annotations

import json
import time

import rclpy
from rclpy.qos import DurabilityPolicy, QoSProfile
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState

from roc.ros.content_filter import ContentFilter
from roc.ros.raw_subscription import Receiver

EXPRESSIONS = [
    ("header.frame_id = 'arm'", []), ("header.frame_id <> %0", ["arm"]), ("header.frame_id LIKE 'a%'", []),
    ("header.frame_id LIKE '_r_'", []), ("header.frame_id MATCH 'b.*e'", []), ("header.stamp.sec > 2", []),
    ("header.stamp.sec BETWEEN %0 AND %1", ["1", "3"]), ("header.stamp.sec NOT BETWEEN 1 AND 3", []),
    ("position[0] >= 0.5 AND position[0] < 2.25", []), ("position[1] = -1.5 OR velocity[0] > 10", []),
    ("NOT (header.frame_id = 'arm' OR header.stamp.nanosec <= 1e3)", []), ("name[0] = name[1]", []),
    ("header.stamp.sec = 0x3", []), ("position[0] > velocity[0]", []),
]


def messages() -> list[JointState]:
    found = []
    for index, frame in enumerate(["arm", "base", "bare", "ark", "", "arm"]):
        message = JointState(name=[f"n{index}", f"n{index}" if index == 3 else "x"],
                             position=[index * 0.5, -1.5 * (index % 3)], velocity=[4.0 - index, 0.0], effort=[0.0, 0.0])
        message.header.frame_id = frame
        message.header.stamp.sec, message.header.stamp.nanosec = index, index * 1000
        found.append(message)
    return found


def main() -> None:
    rclpy.init()
    node = rclpy.create_node("content_filter_oracle")
    latched = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    publisher = node.create_publisher(JointState, "/joints", latched)
    sent = messages()
    for message in sent:
        publisher.publish(message)
    receiver = Receiver(node)
    for key, (expression, parameters) in enumerate(EXPRESSIONS):
        content_filter = ContentFilter(expression, parameters)
        content_filter.check(JointState)
        unfiltered = receiver.subscribe(key, JointState, "/joints", latched,
                                        (content_filter.expression, content_filter.parameters))
        assert unfiltered is None, unfiltered
    delivered: dict[int, list[str]] = {key: [] for key in range(len(EXPRESSIONS))}
    started = time.monotonic()
    while time.monotonic() - started < 20:  # until all came: quiet for a second after the first two
        batch = receiver.batch(1.0)
        for key, data, _ in batch:
            delivered[key].append(deserialize_message(data, JointState).name[0])
        if not batch and time.monotonic() - started > 2:
            break
    for key, (expression, parameters) in enumerate(EXPRESSIONS):
        accepted = [m.name[0] for m in sent if ContentFilter(expression, parameters).accepts(m)]
        print(json.dumps({"expression": expression, "fast_dds": sorted(delivered[key]), "roc": sorted(accepted)}))
    receiver.close()


if __name__ == "__main__":
    main()
