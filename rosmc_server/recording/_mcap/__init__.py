"""The journal's own MCAP layer: writing, damage-tolerant reading and recovery.

Three parts over a shared base, each importing only downwards:

- base: :mod:`.records` (the byte layout of every MCAP record), :mod:`.codec` (ROS 1
  serialisation and schemas), :mod:`.files` (part files, locking, torn tails) and
  :mod:`.layout` (the fixed channel list a journal declares);
- writing: :mod:`.write` (the data section and the open part file, one append per write);
- reading: :mod:`.scan` (a sequential walk that keeps every intact record), with
  :mod:`.checks` (what a record must agree with) and :mod:`.resync` (where trusted records
  start again after damage);
- recovery: :mod:`.reopen` (scan the last part, cut a torn tail, continue or start a part).

Why not ``mcap.writer.Writer`` and ``mcap.reader``: the journal must put each acknowledged
change on disk as one ``write`` (and ``fsync``) before the server answers, so it writes one
chunk per message and never buffers, and it must know the file offset of every record to
resume after a crash. ``mcap``'s writer buffers chunks until they fill or the file closes
(a crash loses the open chunk) and exposes no offsets to continue a file at. ``mcap``'s
readers either need the summary a killed writer never wrote, or stop at the first damaged
record; the scan here skips damaged bytes and keeps every intact record after them. The
files written are plain MCAP: tests read them back with ``mcap``'s own readers, and
``rosmc export`` (:mod:`rosmc_server.recording.export`) uses ``mcap``'s writer for files
that need no durability.
"""
