"""Publish a simulated sensor reading on /readings, 5 times a second."""

import math

from rclpy.node import Node
from rclpy.task import Future

from demo_interfaces.msg import Reading
from demo_py.run import run_until_done


class ReadingPublisher(Node):

    def __init__(self):
        super().__init__('reading_publisher')
        self.unit = self.declare_parameter('unit', 'raw').value
        rate = self.declare_parameter('rate', 5.0).value
        # Stop after this many messages; 0 publishes forever.
        self.max_count = self.declare_parameter('max_count', 0).value
        self.count = 0
        self.done = Future()
        self.publisher = self.create_publisher(Reading, 'readings', 10)
        self.timer = self.create_timer(1.0 / rate, self.publish_reading)

    def publish_reading(self):
        self.count += 1
        msg = Reading()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = 'sensor'
        msg.value = 20.0 + math.sin(self.count / 5.0)
        msg.unit = self.unit
        self.publisher.publish(msg)
        self.get_logger().info(f'Publishing reading {self.count}: {msg.value:.3f} {msg.unit}')
        if self.count == self.max_count:
            self.timer.cancel()
            self.done.set_result(self.count)


def main(args=None):
    run_until_done(ReadingPublisher, args)


if __name__ == '__main__':
    main()
