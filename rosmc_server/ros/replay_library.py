"""The library a replay serves: the one the recording ran with.

The mission server journals its skill library (``/rosmc/library``, once per part file), so
a replay's clients (the marker node, the command GUI, ``rosmc``) ask the replay for it as
they ask a live server, and show a mission made with a custom library with that library.
A recording made before journals held the library gets the shipped Mars team library,
with a warning.

Serves (behind the replay's prefix) ``/rosmc/get_library`` (rosmc/GetLibrary).
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import rosmc.srv as wire_srv
import rospy

from .. import interface
from ..conversions import library_to_msg
from ..core import load_library
from ..recording.playback import Playlist

_log = logging.getLogger(__name__)

GET_LIBRARY = interface.service_name("get_library")
SHIPPED_LIBRARY = Path(__file__).resolve().parents[1] / "config" / "mars_team.yaml"


def recorded_library(playlist: Playlist) -> Any:
    """The ``rosmc/Library`` the recording ran with (its last one), or the shipped one."""
    records = playlist.records_of(interface.LIBRARY_TOPIC)
    if records:
        return records[-1].message
    _log.warning(
        "the recording holds no library (it was made before journals recorded one); "
        "serving the shipped library %s",
        SHIPPED_LIBRARY.name,
    )
    return library_to_msg(load_library(SHIPPED_LIBRARY))


def serve_library(playlist: Playlist, prefix: str) -> rospy.Service:
    """Serve the recording's library as ``<prefix>/rosmc/get_library``; returns the service."""
    response = wire_srv.GetLibraryResponse(library=recorded_library(playlist))
    return rospy.Service(
        interface.prefixed(GET_LIBRARY, prefix), wire_srv.GetLibrary, lambda _request: response
    )
