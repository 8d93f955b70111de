"""What lets a conversion run apart from its caller, below the readers and builders: the
bounded child process (`bounded`, `bounded_child`) with its time and memory budget (`budget`),
the reads it made, kept so that the caller builds the same spec without opening a file
(`replay`), and what it is doing, shared as progress (`stages`)."""

__all__: list[str] = []  # its modules are imported by name
