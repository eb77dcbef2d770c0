"""The operator services that cost the whole mission: get, save and load.

Part of the mission server's operator services (see :mod:`.operator_services`, which
advertises them): ``/rosmc/get_mission`` (rosmc/GetMission), ``/rosmc/save_mission``
(rosmc/SaveMission) and ``/rosmc/load_mission`` (rosmc/LoadMission).

A mission of 10,000 skills is megabytes of YAML or of message, so none of them builds it
afresh: GetMission answers with the snapshot of the current revision, serialized once
(see :class:`~rosmc_server.conversions.packing.SnapshotPacker`); SaveMission reuses the
file lines of unchanged skills (:class:`~rosmc_server.core.files.persistence.MissionDumper`)
and returns the document only to a client that needs it; LoadMission parses and checks
the document and serializes the new skills before it takes the server's lock.
"""

from __future__ import annotations

import gc
import logging
import time
from pathlib import Path
from typing import Any

import rosmc.srv as srv
import rospy

from ..conversions.packing import PackedGetMissionResponse
from ..conversions.request_fields import base_of
from ..core import (
    InvalidRequest,
    MissionEvent,
    MissionFileError,
    Unavailable,
    load_mission,
    parse_mission,
)
from ..core.collector import collector_paused
from ..core.files.persistence import MissionDumper, write_document
from ..core.validation import check_file_path
from .allocator import release_free_memory
from .server_host import ServerHost

_log = logging.getLogger(__name__)


def host_path(path: str, mission_dir: Path) -> Path:
    """A mission file path on the server's host, confined to ``mission_dir``.

    Anybody on the ROS graph can call the services, so the server touches files
    only below one directory; relative paths are taken from there.
    """
    check_file_path(path)  # no NUL (the system refuses it), no line break, not too long
    root = mission_dir.expanduser().resolve()
    target = (root / Path(path).expanduser()).resolve()
    if not target.is_relative_to(root):
        raise InvalidRequest(
            f"the server reads and writes mission files only under {root}; "
            "pass the document itself to save or load elsewhere"
        )
    return target


def make_folder(folder: Path) -> None:
    """Create ``folder`` (and its parents) for a mission file; MissionFileError if it cannot."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise MissionFileError(
            f"{folder}: cannot create the folder for the mission file ({error.strerror})"
        ) from error


class WholeMissionServices:
    """Handlers of GetMission, SaveMission and LoadMission."""

    def __init__(self, server: ServerHost) -> None:
        self._server = server
        self._dumper = MissionDumper()

    def get_mission(self, req: Any) -> Any:
        """The mission snapshot of the current revision, serialized once and shared."""
        try:
            server = self._server
            return PackedGetMissionResponse(
                server.snapshot_msg(), server.journal_alert, server.epoch
            )
        except Unavailable as error:  # the journal failed: no mission may be shown, not even
            raise rospy.ServiceException(str(error)) from None  # an empty one
        except Exception:  # a server fault must not reach the caller as a stack trace
            _log.exception("service get_mission failed")
            return srv.GetMissionResponse()

    def save_mission(self, req: Any, resp: Any) -> None:
        """Write the mission on the server's host and/or return it as a document."""
        with self._server.locked():
            content = self._server.mission.state.content()
            revision = self._server.mission.revision
        document = self._dumper.dump(content, revision)
        if req.path:
            mission_dir = self._server.config.mission_dir
            target = host_path(req.path, mission_dir)
            make_folder(target.parent)  # "team/plan.yaml" may name a folder not made yet
            write_document(target, document)
            resp.path_written = str(target)
        if req.return_document or not req.path:
            resp.document = document
        resp.revision = revision

    def load_mission(self, req: Any, resp: Any) -> MissionEvent:
        """Replace the mission with a document, or a file on the server's host."""
        if bool(req.path) == bool(req.document):
            raise InvalidRequest("give exactly one of a path and a document to load")
        library = self._server.library
        started = time.perf_counter()
        # The save cache's lines are of the skills a load replaces: dropped before the
        # document is read, they are not held beside it (a failed load only costs the next
        # save its cache).
        self._dumper = MissionDumper()
        # So are the snapshot's bytes: the new mission's are made from its skills.
        self._server.drop_snapshot()
        with collector_paused():  # the new mission is acyclic: nothing for it to find
            if req.path:
                mission_dir = self._server.config.mission_dir
                content, _ = load_mission(host_path(req.path, mission_dir), library)
                source = req.path
            else:
                try:
                    content, _ = parse_mission(req.document, library, "the document")
                except RecursionError:  # the YAML parser recurses once per nesting level
                    too_deep = "the document nests its data too deeply to read"
                    raise InvalidRequest(too_deep) from None
                source = "a document"
                # rospy holds a persistent connection's request until its next one.
                req.document = ""
            read = time.perf_counter()
            # Serialized now, outside the server lock: the new mission's journal snapshot,
            # written before the load is acknowledged, then only joins the bytes.
            self._server.prepare_snapshot(content)
        serialized = time.perf_counter()
        event = self._server.apply(lambda m: m.load(content, source, base_revision=base_of(req)))
        assert event is not None
        self._dumper = MissionDumper()  # again: a save meanwhile filled it with the old skills
        _log.info(
            "loaded %d skills from %s: read and checked in %.0f ms, serialized in %.0f ms, "
            "applied and journaled in %.0f ms",
            sum(map(len, content.tasks.values())), source, 1000 * (read - started),
            1000 * (serialized - read), 1000 * (time.perf_counter() - serialized),
        )  # fmt: skip
        # The loaded mission lives until it is replaced and is then freed by reference
        # counting; kept out of the collector's way, it does not lengthen every later
        # full collection (tens of milliseconds at 10,000 skills).
        gc.freeze()
        release_free_memory()
        return event
