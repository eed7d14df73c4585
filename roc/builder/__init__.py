"""``roc work build``: packages become engine tasks run by build-type handlers."""
