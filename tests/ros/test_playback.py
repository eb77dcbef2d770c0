"""The replay's clock, its records by time and its TF stamp shift, without a ROS graph.

The clock runs on a hand-driven time source, so every position here is exact; the
waits that block use threads and say only whether they woke for the due time or for a
change.
"""

from __future__ import annotations

import threading

import pytest

from rosmc_server.core import InvalidRequest
from rosmc_server.recording import JournalRecord
from rosmc_server.recording.playback import (
    MAX_RATE,
    PlaybackClock,
    Playlist,
    StampShift,
)

T0 = 1_700_000_000_000_000_000


class Time:
    """A monotonic clock the test moves."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def now() -> Time:
    return Time()


def started(
    now: Time, duration: float = 60.0, start: float = 0.0, rate: float = 1.0
) -> PlaybackClock:
    clock = PlaybackClock(duration, start, rate, monotonic=now)
    clock.start()
    return clock


def test_the_position_stands_until_started_then_advances_at_the_rate(now: Time) -> None:
    clock = PlaybackClock(60.0, 5.0, 2.0, monotonic=now)
    now.now += 3.0  # the warm-up: subscribers connect
    assert clock.status().position == 5.0
    clock.start()
    now.now += 3.0
    status = clock.status()
    assert (status.position, status.rate, status.paused, status.seeks) == (11.0, 2.0, False, 0)
    now.now += 100.0
    assert clock.status().position == 60.0 and clock.status().ended


def test_pause_holds_the_position_and_resume_goes_on_from_it(now: Time) -> None:
    clock = started(now)
    now.now += 4.0
    assert clock.pause().position == 4.0
    changes = clock.changes
    assert clock.pause().paused and clock.changes == changes  # paused already: no change
    now.now += 10.0
    assert clock.status().position == 4.0
    assert not clock.resume().paused
    now.now += 1.5
    assert clock.status().position == 5.5


def test_seek_moves_absolute_or_relative_clamped_and_counts(now: Time) -> None:
    clock = started(now)
    now.now += 20.0
    assert clock.seek(-5.0, relative=True).position == 15.0
    assert clock.seek(7.5).position == 7.5
    assert clock.seek(1e9).position == 60.0
    assert clock.seek(-1e9, relative=True).position == 0.0
    assert clock.status().seeks == 4
    paused = clock.pause()
    assert clock.seek(30.0).paused, "a seek keeps a paused replay paused"
    assert clock.status().seeks == paused.seeks + 1


def test_resume_at_the_end_plays_again_from_the_start(now: Time) -> None:
    clock = started(now, duration=10.0)
    now.now += 50.0
    assert clock.status().ended
    again = clock.resume()
    assert (again.position, again.seeks, again.ended) == (0.0, 1, False)


def test_the_rate_changes_from_the_position_on(now: Time) -> None:
    clock = started(now)
    now.now += 10.0
    assert clock.set_rate(4.0).position == 10.0
    now.now += 2.0
    assert clock.status().position == 18.0


def test_bad_requests_are_refused_and_change_nothing(now: Time) -> None:
    clock = started(now)
    now.now += 3.0
    before, changes = clock.status(), clock.changes
    for bad in (0.0, -1.0, MAX_RATE * 2, float("nan")):
        with pytest.raises(InvalidRequest, match="rate must be between"):
            clock.set_rate(bad)
    with pytest.raises(InvalidRequest, match="seeks to a number"):
        clock.seek(float("inf"))
    assert clock.status() == before and clock.changes == changes
    with pytest.raises(InvalidRequest):
        PlaybackClock(10.0, rate=0.0)


def test_wait_is_due_at_once_for_a_past_position(now: Time) -> None:
    clock = started(now)
    now.now += 5.0
    assert clock.wait(4.0) is True
    assert clock.wait(5.0) is True


def test_wait_wakes_on_a_change_and_on_close() -> None:
    clock = PlaybackClock(60.0)
    clock.start()
    clock.pause()  # a paused clock never reaches a later position by itself
    woke: list[bool] = []
    since = clock.changes
    waiter = threading.Thread(target=lambda: woke.append(clock.wait(30.0, since)))
    waiter.start()
    clock.seek(10.0)
    waiter.join(10.0)
    assert woke == [False]
    since = clock.changes
    waiter = threading.Thread(target=lambda: woke.append(clock.wait(None, since)))
    waiter.start()
    clock.close()
    waiter.join(10.0)
    assert woke == [False, False]
    assert clock.wait(None) is False, "a closed clock never blocks"


def test_a_change_before_the_wait_is_not_missed() -> None:
    clock = PlaybackClock(60.0)
    clock.start()
    clock.pause()
    since = clock.changes
    clock.resume()  # between reading `changes` and waiting: the wait returns at once
    assert clock.wait(59.0, since) is False


def record(topic: str, seconds: float) -> JournalRecord:
    return JournalRecord(topic, T0 + round(seconds * 1e9), None)


def test_playlist_finds_records_by_time() -> None:
    records = [record("/b", 2.0), record("/a", 0.0), record("/a", 1.0), record("/b", 1.0)]
    playlist = Playlist(records, T0)
    assert [(r.topic, playlist.offset(i)) for i, r in enumerate(playlist.records)] == [
        ("/a", 0.0),
        ("/a", 1.0),
        ("/b", 1.0),
        ("/b", 2.0),
    ]
    assert [playlist.index_after(t) for t in (-1.0, 0.0, 0.5, 1.0, 2.0)] == [0, 1, 1, 3, 4]
    assert playlist.latest("/a", 0.5) is playlist.records[0]
    assert playlist.latest("/a", 5.0) is playlist.records[1]
    assert playlist.latest("/b", 1.0) is playlist.records[2]
    assert playlist.latest("/b", 0.99) is None
    assert playlist.latest("/none", 5.0) is None


def test_stamps_stay_as_recorded_while_playing_on() -> None:
    shift = StampShift()
    assert [shift.apply([t, t + 5]) for t in (100, 200, 300)] == [0, 0, 0]


def test_after_a_seek_back_stamps_continue_past_the_newest_published() -> None:
    shift = StampShift()
    shift.apply([1_000, 5_000])
    shift.moved()  # back to a message stamped 2_000
    moved = shift.apply([2_000, 2_500])
    assert 2_000 + moved == 5_000 + StampShift.MARGIN
    assert shift.apply([3_000]) == moved, "the shift holds while playing on"
    shift.moved()  # forward: already past the newest, nothing more to add
    assert shift.apply([9_000_000]) == moved
    shift.moved()  # back again, to the very first message
    again = shift.apply([1_000])
    assert again > moved and 1_000 + again > 9_000_000 + moved
