"""roc bag: record, play, inspect and convert rosbag2 bags (MCAP and sqlite3)."""
