"""Package environments described by colcon's ``.dsv`` files, applied in Python or rendered to shell."""
