"""Independent reference implementations the tests compare armdyn against (not part of armdyn)."""
