"""A world server's conversions: read in a bounded child, the spec built once here from what the
child read (`served`), and what that child imports before it forks (`warm`)."""

__all__: list[str] = []  # its modules are imported by name
