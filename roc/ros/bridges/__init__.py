"""Servers that carry one ROS domain elsewhere: another domain (domains.py, services.py), a Zenoh
session (zenoh_link.py, zenoh_services.py), Foxglove clients (foxglove_server.py)."""
