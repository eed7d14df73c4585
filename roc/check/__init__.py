"""roc graph check: declared expectations of a running ROS system, probed as tasks of roc's engine."""
