"""What the tests share: running roc and the oracles (colcon, ros2, ros2 launch) on fixture workspaces and
live graphs, the servers the tests start, the ROS domains each test file takes, and the conventions of
the manual's runnable examples. The scripts the tests run as ROS nodes are in ``tests/nodes/``."""
