"""ROS 2 graph tools built on rclpy (imported lazily: rclpy is slow to load)."""
