"""The ``rosmc`` command line: a scriptable client of the mission server's operator interface.

Run ``rosmc --help`` for the commands. The command functions use
:class:`rosmc_server.ros.client.MissionClient`; formatting lives in :mod:`rosmc_server.text`.
"""

from .main import main

__all__ = ["main"]
