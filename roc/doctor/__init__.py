"""``roc doctor``: checks of what most often keeps ROS 2 nodes from talking (the environment, the
network and multicast, the live graph), each a Finding, and ros2 doctor's reports."""
