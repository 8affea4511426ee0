"""Exception types shared by the whole package.

Every error a user can cause (bad file, bad field, bad argument) derives from
:class:`SensingAntennaError`, so the command line can print it as one line without a traceback.
"""

from __future__ import annotations


class SensingAntennaError(Exception):
    """Base class for errors caused by input: files, fields, arguments."""
