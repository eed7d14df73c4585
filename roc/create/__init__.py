"""``roc work create``: new ROS 2 packages from jinja2 templates (like ``ros2 pkg create``)."""
