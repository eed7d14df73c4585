"""Generated shell scripts: per-package hooks and scripts, install-level setup scripts."""
