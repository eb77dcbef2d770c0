"""The emulated radio link: latency in order, seeded random loss, blackouts."""

from __future__ import annotations

import random

import pytest

from rosmc_sim.core.delay_line import DelayLine, LineStats


def test_items_arrive_after_the_latency_in_sending_order() -> None:
    line: DelayLine[str] = DelayLine(latency=2.0)
    line.push("a", 10.0)
    line.push("b", 10.0)  # same send time: order kept
    line.push("c", 10.5)
    assert line.due(11.99) == []
    assert line.in_flight() == 3
    assert line.due(12.0) == ["a", "b"]
    assert line.due(12.2) == []
    assert line.due(100.0) == ["c"]
    assert line.in_flight() == 0
    assert line.stats == LineStats(sent=3, delivered=3)


def test_zero_latency_delivers_on_the_next_poll() -> None:
    line: DelayLine[int] = DelayLine()
    for number in range(100):
        line.push(number, 5.0)
    assert line.due(5.0) == list(range(100))


def test_a_late_poll_gets_everything_due_in_order() -> None:
    line: DelayLine[int] = DelayLine(latency=0.3)
    sent = [(i, 1.0 + 0.01 * i) for i in range(50)]
    for item, when in sent:
        line.push(item, when)
    assert line.due(1.3 + 0.01 * 24) == list(range(25))
    assert line.due(10.0) == list(range(25, 50))


def test_drop_probability_with_a_seeded_generator_is_reproducible() -> None:
    def run(seed: int) -> tuple[list[int], LineStats]:
        line: DelayLine[int] = DelayLine(drop=0.25, rng=random.Random(seed))
        for number in range(4000):
            line.push(number, 0.0)
        return line.due(0.0), line.stats

    delivered, stats = run(7)
    assert (delivered, stats) == run(7)
    assert delivered != run(8)[0]
    assert stats.dropped == pytest.approx(1000, abs=120)  # > 4 standard deviations
    assert stats.dropped + stats.delivered == stats.sent == 4000
    assert delivered == sorted(delivered)  # the survivors keep their order


@pytest.mark.parametrize(("drop", "expected"), [(0.0, 100), (1.0, 0)])
def test_no_and_total_loss(drop: float, expected: int) -> None:
    line: DelayLine[int] = DelayLine(drop=drop, rng=random.Random(1))
    for number in range(100):
        line.push(number, 0.0)
    assert len(line.due(0.0)) == expected


def test_a_blackout_loses_what_is_in_flight_and_what_is_sent_during_it() -> None:
    line: DelayLine[str] = DelayLine(latency=1.0)
    line.push("before", 0.0)
    line.push("also before", 0.5)
    line.set_blackout(True)
    assert line.in_flight() == 0
    line.push("during", 0.7)
    assert line.due(5.0) == []
    line.set_blackout(False)
    line.push("after", 6.0)
    assert line.due(6.9) == []
    assert line.due(7.0) == ["after"]
    assert line.stats == LineStats(sent=4, delivered=1, dropped=0, blacked_out=3)


def test_starting_a_blackout_twice_counts_losses_once() -> None:
    line: DelayLine[str] = DelayLine(latency=1.0)
    line.push("x", 0.0)
    line.set_blackout(True)
    line.set_blackout(True)
    assert line.stats.blacked_out == 1


def test_ending_a_blackout_that_never_started_is_harmless() -> None:
    line: DelayLine[str] = DelayLine(latency=1.0)
    line.push("x", 0.0)
    line.set_blackout(False)
    assert line.due(1.0) == ["x"]


def test_delivered_items_are_not_lost_by_a_later_blackout() -> None:
    line: DelayLine[str] = DelayLine(latency=1.0)
    line.push("x", 0.0)
    assert line.due(1.0) == ["x"]
    line.set_blackout(True)
    assert line.stats.blacked_out == 0
