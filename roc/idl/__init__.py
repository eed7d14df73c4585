"""Interface definition conversion (.proto <-> .msg)."""
