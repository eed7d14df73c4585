"""Event handlers: the console, log files, stored results and JSON events for CI."""
