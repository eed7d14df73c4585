"""Command-line entry point, argument parsing and shell completion."""
