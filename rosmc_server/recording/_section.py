"""What a journal writer must remember to close its file with a proper MCAP summary."""

from dataclasses import dataclass, field

from mcap.opcode import Opcode

from rosmc_server.recording import _format as fmt
from rosmc_server.recording._scan import ScanResult


@dataclass
class SummaryState:
    """Schemas, channels, chunk indexes and statistics of the data section written so far."""

    schemas: dict[int, fmt.SchemaRecord] = field(default_factory=dict)
    channels: dict[int, fmt.ChannelRecord] = field(default_factory=dict)
    chunk_indexes: list[fmt.ChunkIndexRecord] = field(default_factory=list)
    counts: dict[int, int] = field(default_factory=dict)
    start_time: int = 0
    end_time: int = 0

    @classmethod
    def from_scan(cls, scan: ScanResult) -> "SummaryState":
        """Rebuild the state of the data section a scan found."""
        state = cls(dict(scan.schemas), dict(scan.channels), list(scan.chunk_indexes))
        for msg in scan.messages:
            state.count(msg.channel_id, msg.log_time)
        return state

    def count(self, channel_id: int, log_time: int) -> int:
        """Count one more message; return its sequence number on its channel."""
        sequence = self.counts.get(channel_id, 0)
        if not self.counts:
            self.start_time = self.end_time = log_time
        self.start_time = min(self.start_time, log_time)
        self.end_time = max(self.end_time, log_time)
        self.counts[channel_id] = sequence + 1
        return sequence & 0xFFFFFFFF

    def closing_bytes(self, data_end: int) -> bytes:
        """Return Data End, the summary, the footer and the closing magic.

        Args:
            data_end: File offset at which the Data End record will be written.
        """
        closing = fmt.data_end()
        summary_start = data_end + len(closing)
        groups = [
            (Opcode.SCHEMA, b"".join(fmt.schema(s) for s in self.schemas.values())),
            (Opcode.CHANNEL, b"".join(fmt.channel(c) for c in self.channels.values())),
            (Opcode.STATISTICS, self._statistics()),
            (Opcode.CHUNK_INDEX, b"".join(fmt.chunk_index(c) for c in self.chunk_indexes)),
        ]
        summary = b""
        offsets = b""
        for opcode, group in groups:
            if group:
                offsets += fmt.summary_offset(opcode, summary_start + len(summary), len(group))
                summary += group
        summary_offset_start = summary_start + len(summary)
        summary += offsets
        footer = fmt.footer(summary_start, summary_offset_start, summary)
        return closing + summary + footer + fmt.MAGIC

    def _statistics(self) -> bytes:
        return fmt.statistics(
            schemas=len(self.schemas),
            channels=len(self.channels),
            chunks=len(self.chunk_indexes),
            counts=self.counts,
            start=self.start_time,
            end=self.end_time,
        )
