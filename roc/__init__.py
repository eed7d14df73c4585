"""roc: a fast, dependable command-line tool for ROS 2 workspaces."""

__version__ = "0.1.0"
