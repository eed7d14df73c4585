"""Start the reading publisher and listener with config/params.yaml."""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    params = os.path.join(get_package_share_directory('demo_py'), 'config', 'params.yaml')
    return LaunchDescription([
        Node(package='demo_py', executable='reading_publisher',
             parameters=[params], output='screen'),
        Node(package='demo_py', executable='reading_listener',
             parameters=[params], output='screen'),
    ])
