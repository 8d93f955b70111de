"""Conversion errors: each names what is wrong, where (file, link, joint) and the fix."""

from __future__ import annotations


class ConversionError(Exception):
    """Base class for every error a description file can cause.

    Subclasses take the facts as arguments and build the message, so that every
    message says what, where and how to fix it.
    """


class InputFileError(ConversionError):
    """The input file is missing, unreadable or of an unknown format."""

    def __init__(self, path: str, problem: str, fix: str) -> None:
        super().__init__(f"{path}: {problem}; {fix}")
        self.path = path
