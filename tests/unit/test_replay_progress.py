"""A pause answers after the records due until it are out (rosmc_server/ros/replay_progress)."""

from __future__ import annotations

import threading
from collections.abc import Callable

from rosmc_server.ros.replay_progress import ReplayProgress

OFFSETS = [0.0, 1.0, 2.0, 3.0, 4.0]  # seconds of each record since the start


def due_at(position: float) -> Callable[[int], bool]:
    """Whether record ``index`` is due at ``position``."""
    return lambda index: index < len(OFFSETS) and OFFSETS[index] <= position


def test_a_pause_waits_for_the_record_that_came_due_before_it() -> None:
    lock = threading.RLock()
    progress = ReplayProgress(lock)
    progress.playing(True)
    progress.next_record(3)  # record 3 (at 3 s) came due, the playing thread is about to send it
    order: list[str] = []
    asked = threading.Event()  # the pause has found record 3 due: it waits

    def due(index: int) -> bool:
        asked.set()
        return due_at(3.5)(index)  # paused at 3.5 s

    def playing_thread() -> None:
        asked.wait()
        order.append("record 3 published")
        progress.next_record(4)

    thread = threading.Thread(target=playing_thread)
    thread.start()
    progress.await_due(due, threading.Event())
    order.append("pause answered")
    thread.join()
    assert order == ["record 3 published", "pause answered"]


def test_nothing_is_awaited_when_nothing_is_due_or_nothing_plays() -> None:
    progress = ReplayProgress(threading.RLock())
    progress.playing(True)
    progress.next_record(4)
    progress.await_due(due_at(3.5), threading.Event())  # record 4 is not due: at once
    progress.next_record(0)
    progress.playing(False)
    progress.await_due(due_at(3.5), threading.Event())  # the replay ended: at once
    progress.playing(True)
    stopped = threading.Event()
    stopped.set()
    progress.await_due(due_at(3.5), stopped)  # stopping: at once


def test_a_seek_answers_once_its_state_is_out() -> None:
    progress = ReplayProgress(threading.RLock())
    progress.playing(True)
    order: list[str] = []

    def playing_thread() -> None:
        with progress.condition:
            order.append("state at seek 1 published")
            progress.seek_out(1)

    thread = threading.Thread(target=playing_thread)
    thread.start()
    progress.await_seek(1, threading.Event())
    order.append("seek answered")
    thread.join()
    assert order == ["state at seek 1 published", "seek answered"]
