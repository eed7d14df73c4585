"""rosbag2 bags without rclpy: metadata, storage (MCAP, sqlite3), compression, reading and writing.

The recorder and the player, which need the ROS graph, live in ``roc.bag.transport``."""
