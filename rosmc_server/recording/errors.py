"""Errors of the MCAP mission journal."""

from rosmc_server.core.errors import RosmcError


class JournalError(RosmcError):
    """A journal cannot be read, resumed or written; the message names the file."""
