"""Files a user names: inputs read with bounds and clear errors (`input_files`), outputs written
atomically and only where asked (`output_files`), and the package path variables a description
resolves through (`package_env`)."""

__all__: list[str] = []  # its modules are imported by name
