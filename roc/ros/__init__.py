"""ROS 2 graph tools built on rclpy (imported lazily: rclpy is slow to load)."""

import logging

# what the graph layer logs reaches a log only where one is set up (the daemon's); it never prints
logging.getLogger(__name__).addHandler(logging.NullHandler())
