"""Exception types shared by the whole package.

Every error a user can cause (bad file, bad field, bad argument) derives from
:class:`SensingAntennaError`, so the command line can print it as one line without a traceback.
"""

from __future__ import annotations


class SensingAntennaError(Exception):
    """Base class for errors caused by input: files, fields, arguments."""


class FieldError(SensingAntennaError, ValueError):
    """A named field of a configuration file is missing, unknown or invalid.

    The message reads ``<source>: <field>: <problem>``; the parts stay available as attributes.
    """

    def __init__(self, field_name: str, problem: str, source: str | None = None) -> None:
        self.field_name = field_name
        self.problem = problem
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{field_name}: {problem}")
