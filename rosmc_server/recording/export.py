"""``rosmc export``: a recording as one MCAP file for Foxglove and other MCAP tools.

The journal is written for durability: one chunk per message, part files, telemetry
stamped by whoever sent it. The export is written for reading, with the ``mcap``
package's own writer:

- chunks of about :data:`CHUNK_BYTES` (zstd), message indexes and a summary, so a viewer
  seeks without reading the whole file; one file, whatever parts the journal had;
- every recorded topic under its own name, with the log time (the server's wall clock
  when it journaled the message) as publish time too, and every header stamp of
  ``/tf`` and ``/rosmc/sim/world`` set to that log time: a simulator stamps them with
  sim time, which would leave a viewer's 3D panel without transforms at the log times;
- the robots and objects drawn as markers in their TF frames (:data:`ROBOTS_TOPIC`,
  ``visualization_msgs/MarkerArray``, the bodies rviz shows), at every recorded TF;
- the mission as text (``std_msgs/String``): the task panel at every revision
  (:data:`TASKS_TOPIC`, as ``rosmc at`` prints it) and one line per change
  (:data:`CHANGES_TOPIC`, as ``rosmc watch`` prints it).
"""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import genpy
from mcap_ros1.writer import Writer
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from rosmc_server.core.views import geometry as geo

from ..conversions import event_from_msg, library_from_msg
from ..conversions.primitives import primitive_msg
from ..core import RosmcError
from ..interface import EVENTS_TOPIC, LIBRARY_TOPIC, MISSION_TOPIC, TF_TOPIC, WORLD_TOPIC
from ..text import format_event, format_tasks
from .errors import JournalError
from .history import MissionHistory
from .reader import JournalRecord, read_journal

CHUNK_BYTES = 512 * 1024
"""Uncompressed bytes per chunk: a few chunks for a short mission, seeks stay cheap."""
ROBOTS_TOPIC = "/rosmc/export/robots"
TASKS_TOPIC = "/rosmc/export/tasks"
CHANGES_TOPIC = "/rosmc/export/changes"
LABEL_HEIGHT = 0.6  # m: the name above each body
LABEL_Z = 3.0


@dataclass(frozen=True)
class ExportSummary:
    """What :func:`export_recording` wrote: the file and the messages per topic."""

    path: Path
    counts: Mapping[str, int]
    skipped: str  # what the journal lacked (damage, lost revisions), "" if nothing

    @property
    def total(self) -> int:
        """Messages written."""
        return sum(self.counts.values())


def export_recording(
    journal: str | Path, out: str | Path, *, overwrite: bool = False, chunk_size: int = CHUNK_BYTES
) -> ExportSummary:
    """Write the recording ``journal`` as an indexed, chunked MCAP file ``out``.

    Raises:
        JournalError: ``out`` exists (and not ``overwrite``), or the journal is unreadable.
    """
    out = Path(out)
    if out.exists() and not overwrite:
        raise JournalError(f"{out} exists; give --force to overwrite it")
    result = read_journal(journal)
    history = MissionHistory(result)
    models = _models(result.records)
    counts: Counter[str] = Counter()
    partial = out.with_name(f".{out.name}.partial")  # a reader never sees half a file
    try:
        with partial.open("wb") as stream:
            writer = Writer(stream, chunk_size=chunk_size)
            for record in result.records:
                for topic, msg in _exported(record, history, models):
                    writer.write_message(topic, msg, record.log_time, record.log_time)
                    counts[topic] += 1
            writer.finish()  # type: ignore[no-untyped-call]
        os.replace(partial, out)
    except OSError as err:
        partial.unlink(missing_ok=True)
        raise JournalError(f"cannot write {out}: {err.strerror or err}") from err
    return ExportSummary(out, dict(counts), "; ".join(history.problems))


def _exported(
    record: JournalRecord, history: MissionHistory, models: Mapping[str, str]
) -> Iterator[tuple[str, Any]]:
    """The messages one journal record becomes in the export."""
    msg, stamp = record.message, _stamp(record.log_time)
    if record.topic == TF_TOPIC:
        for transform in msg.transforms:
            transform.header.stamp = stamp
        yield TF_TOPIC, msg
        yield ROBOTS_TOPIC, robot_markers(msg, models, stamp)
        return
    if record.topic == WORLD_TOPIC:
        for marker in msg.markers:
            marker.header.stamp = stamp
    yield record.topic, msg
    if record.topic in (EVENTS_TOPIC, MISSION_TOPIC):
        yield from _mission_text(record, history)


def _mission_text(record: JournalRecord, history: MissionHistory) -> Iterator[tuple[str, Any]]:
    revision = int(record.message.revision)
    if record.topic == EVENTS_TOPIC:
        line = _event_line(record.message)
        if line:  # an event that does not decode is still exported as recorded
            yield CHANGES_TOPIC, String(data=line)
    try:
        state = history.at_revision(revision)
    except RosmcError:
        return  # a revision the history could not rebuild (see ExportSummary.skipped)
    title = f"{history.path.name} at {history.seconds(record.log_time):.1f} s"
    yield TASKS_TOPIC, String(data=format_tasks(state, title))


def _event_line(msg: Any) -> str:
    try:
        return format_event(event_from_msg(msg))
    except RosmcError:
        return ""


def robot_markers(tf: Any, models: Mapping[str, str], stamp: genpy.Time) -> MarkerArray:
    """The body and name of every agent ``tf`` (tf2_msgs/TFMessage) places, in its frame."""
    out = MarkerArray()
    for transform in tf.transforms:
        frame = str(transform.child_frame_id)
        agent, _, link = frame.rpartition("/")
        if link != "base_link" or not agent:
            continue
        label = geo.Primitive(
            geo.Shape.TEXT,
            geo.Color(1.0, 1.0, 1.0),
            (0.0, 0.0, LABEL_Z),
            (0.0, 0.0, LABEL_HEIGHT),
            text=agent,
        )
        body = (*geo.agent_body(geo.body_kind(models.get(agent, agent))), label)
        for ident, primitive in enumerate(body):
            marker = primitive_msg(primitive, ident)
            marker.header.frame_id = frame
            marker.header.stamp = stamp
            marker.ns = f"robots/{agent}"
            marker.frame_locked = True
            out.markers.append(marker)
    return out


def _models(records: tuple[JournalRecord, ...]) -> dict[str, str]:
    """Each agent's model as the recorded library names it ({} for an older recording:
    bodies then follow the agents' names)."""
    libraries = [r.message for r in records if r.topic == LIBRARY_TOPIC]
    if not libraries:
        return {}
    return {agent.name: agent.model for agent in library_from_msg(libraries[-1]).agents}


def _stamp(log_time: int) -> genpy.Time:
    return genpy.Time(log_time // 10**9, log_time % 10**9)
