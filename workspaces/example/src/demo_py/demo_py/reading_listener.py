"""Log every reading received on /readings."""

from rclpy.node import Node
from rclpy.task import Future

from demo_interfaces.msg import Reading
from demo_py.run import run_until_done


class ReadingListener(Node):

    def __init__(self):
        super().__init__('reading_listener')
        # Stop after this many messages; 0 listens forever.
        self.max_count = self.declare_parameter('max_count', 0).value
        self.count = 0
        self.done = Future()
        self.subscription = self.create_subscription(Reading, 'readings', self.on_reading, 10)

    def on_reading(self, msg):
        self.count += 1
        self.get_logger().info(
            f'Received reading from {msg.header.frame_id}: {msg.value:.3f} {msg.unit}')
        if self.count == self.max_count:
            self.done.set_result(self.count)


def main(args=None):
    run_until_done(ReadingListener, args)


if __name__ == '__main__':
    main()
