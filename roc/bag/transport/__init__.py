"""The bag recorder and player: the parts of ``roc bag`` that join the ROS graph, so the only part
of ``roc/bag/`` that imports rclpy (through roc.ros's Graph and raw subscriptions). Each runs in the
verb's own process."""
