"""roc: a fast, dependable command-line tool for ROS 2 workspaces."""

try:  # written by the install from the repository's tags (setuptools-scm, pyproject.toml)
    from roc._version import version as __version__
except ImportError:  # a checkout on sys.path that was never installed
    __version__ = "0.0.0+unknown"
