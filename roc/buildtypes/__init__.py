"""Build-type handlers: how each kind of package (ament_cmake, cmake, ament_python, python) is built."""
