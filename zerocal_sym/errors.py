"""User-facing errors.

Every error a user can cause (a bad robot file, a bad data file, an
unreachable pose, a singular or degenerate pose set) is a :class:`ZerocalError`
whose message says what is wrong and where.  The CLI prints it on one line and
exits with status 2; anything else is a bug and keeps its traceback.
"""
from __future__ import annotations


class ZerocalError(Exception):
    """Base class of errors caused by user input.

    Parameters
    ----------
    message : str
        What is wrong.
    where : str, optional
        Where: ``file``, ``file:line``, ``file:line:column``, ``pose 3``, ...
    """

    def __init__(self, message: str, where: str | None = None):
        self.message = message
        self.where = where
        super().__init__(f"{where}: {message}" if where else message)


class RobotFileError(ZerocalError):
    """A robot description that is malformed or describes an unusable robot."""


class DataFileError(ZerocalError):
    """A measurement file that cannot be read as the documented format."""


class PoseError(ZerocalError):
    """A pose that is unreachable, singular, or a pose set that is degenerate."""


class IdentificationError(ZerocalError):
    """An identification that cannot give a calibration (rank, convergence)."""
