#!/usr/bin/env python3
"""Record the committed sample recording ``bags/samples/demo.mcap`` anew (``make sample``).

Runs the demo mission (``rosmc_demo``: mission server, simulated team, scripted operator)
at a high real-time factor, with a full mission snapshot every few events (the server's
own state, which the tests check the replay against), and puts its journal in place of
the sample, unchanged. Nothing is stripped: the sample holds every channel a recording
has (mission events and snapshots, robot reports, agent states, TF, site, score).

Run it after changing a message definition (``tests/ros/test_sample.py`` says when the
sample's embedded definitions differ from the built ones), then commit the new file::

    source env.sh && python tools/record_sample.py          # or: make sample
    python tools/record_sample.py --output /tmp/demo.mcap   # elsewhere
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
SAMPLE = REPO_ROOT / "bags" / "samples" / "demo.mcap"
REAL_TIME_FACTOR = 20.0
SNAPSHOT_EVERY = 20
MAX_BYTES = 1_000_000


def record(output: Path, real_time_factor: float, snapshot_every: int) -> int:
    """Run the demo into a fresh directory and move its journal to ``output``."""
    from rosmc_server.recording import read_journal
    from rosmc_sim import demo

    with tempfile.TemporaryDirectory(prefix="rosmc_sample_") as scratch:
        started = time.time()
        code = demo.main(
            [
                "--real-time-factor",
                str(real_time_factor),
                "--snapshot-every",
                str(snapshot_every),
                "--journal-dir",
                scratch,
            ]
        )
        journal = demo.newest_recording(Path(scratch), started)
        if code != 0 or journal is None:
            print(f"record_sample: the demo failed (exit {code}); {output} is unchanged")
            return 1
        result = read_journal(journal)
        if not result.clean:
            print(f"record_sample: the recording is not clean: {result.warnings}")
            return 1
        size = journal.stat().st_size
        output.parent.mkdir(parents=True, exist_ok=True)
        staged = output.with_name(output.name + ".new")
        shutil.copyfile(journal, staged)
        staged.replace(output)
    counts: dict[str, int] = {}
    for item in result.records:
        counts[item.topic] = counts.get(item.topic, 0) + 1
    print(f"record_sample: wrote {output} ({size} bytes, {len(result.records)} records)")
    for topic, count in sorted(counts.items()):
        print(f"  {topic:24} {count}")
    if size > MAX_BYTES:
        print(f"record_sample: warning: more than {MAX_BYTES} bytes; keep the sample small")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Parse the options and record."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", type=Path, default=SAMPLE, help=f"default: {SAMPLE}")
    parser.add_argument("--real-time-factor", type=float, default=REAL_TIME_FACTOR)
    parser.add_argument("--snapshot-every", type=int, default=SNAPSHOT_EVERY)
    args = parser.parse_args(argv)
    return record(args.output.resolve(), args.real_time_factor, args.snapshot_every)


if __name__ == "__main__":
    sys.exit(main())
