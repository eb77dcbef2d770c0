"""The radio side channel's pure parts: datagram framing, endpoints, contact, command resend."""

from __future__ import annotations

import itertools

import pytest

from rosmc_server.core import InvalidRequest
from rosmc_server.core.robots.link import Outbox
from rosmc_server.core.robots.radio import (
    DIRECTORY_MAX_PERIOD,
    DIRECTORY_PERIOD,
    BeaconPlan,
    ContactWatch,
    DatagramKind,
    next_directory_period,
    parse_endpoint,
)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("10.0.0.11:40000", ("10.0.0.11", 40000)),
        ("[::1]:9", ("::1", 9)),
        ("r1.lan:1", ("r1.lan", 1)),
    ],
)
def test_endpoints_read_as_host_and_port(text: str, expected: tuple[str, int]) -> None:
    assert parse_endpoint(text) == expected


@pytest.mark.parametrize("text", ["", "10.0.0.11", ":40000", "host:0", "host:70000", "host:x"])
def test_malformed_endpoints_are_refused(text: str) -> None:
    with pytest.raises(InvalidRequest, match="host:port"):
        parse_endpoint(text)


def test_contact_returns_only_after_a_silence() -> None:
    watch = ContactWatch(silence=1.5)
    assert not watch.heard("r1", 10.0)  # first contact: nothing stalled to repair
    assert not watch.heard("r1", 11.0)
    assert watch.in_contact("r1", 12.5) and not watch.in_contact("r1", 12.6)
    assert watch.heard("r1", 20.0)  # back after 9 s of silence
    assert not watch.heard("r1", 20.5)
    assert not watch.in_contact("r2", 20.5)


def test_the_first_of_a_series_of_return_beacons_brings_contact_back() -> None:
    watch = ContactWatch(silence=10.0)  # the ground's, for a robot beaconing every 4 s
    assert not watch.heard("r1", 0.0, returning=True)  # first contact: nothing stalled
    assert not watch.heard("r1", 4.0) and not watch.heard("r1", 8.0)
    assert watch.heard("r1", 9.0, returning=True)  # it did not hear the ground: a cut
    assert not watch.heard("r1", 9.5, returning=True)  # the same series
    assert not watch.heard("r1", 10.0)
    assert not watch.heard("r1", 14.0)
    assert watch.heard("r1", 14.5, returning=True)  # a new series
    assert watch.heard("r1", 30.0)  # a plain beacon after a silence


def test_a_robot_beacons_seldom_while_it_hears_the_ground_and_often_while_it_does_not() -> None:
    plan = BeaconPlan(period=0.5, idle_period=4.0, silence=1.5)
    sent = {}
    for tick in range(0, 400):  # 20 s in 50 ms ticks
        now = tick * 0.05
        if 2.0 <= now < 12.0 and tick % 10 == 0:  # the ground heard every 0.5 s
            plan.heard(now)
        kind = plan.due(now)
        if kind is not None:
            sent[round(now, 2)] = kind
    seeking = DatagramKind.RETURN_BEACON
    assert all(k is seeking for t, k in sent.items() if t < 2.0)  # nothing heard yet
    assert sent[2.0] is seeking and sent[2.5] is seeking  # at once on hearing it, twice
    quiet = [t for t, k in sent.items() if 3.0 <= t <= 13.0]
    assert quiet == [3.0, 7.0, 11.0] and all(sent[t] is DatagramKind.BEACON for t in quiet)
    lost = [t for t in sent if t > 13.0]  # last heard at 11.5 s: seeking again, at once
    assert lost[0] == 13.05 and all(sent[t] is seeking for t in lost)
    assert all(b - a <= 0.5 + 1e-9 for a, b in itertools.pairwise(lost))


def test_the_directory_is_read_less_often_while_it_stays_the_same() -> None:
    period = DIRECTORY_PERIOD
    periods = []
    for changed in (True, False, False, False, False, False, False, True, False):
        period = next_directory_period(period, changed)
        periods.append(period)
    assert periods[0] == DIRECTORY_PERIOD
    assert periods[1:4] == [2 * DIRECTORY_PERIOD, 4 * DIRECTORY_PERIOD, 8 * DIRECTORY_PERIOD]
    assert periods[6] == DIRECTORY_MAX_PERIOD  # never longer
    assert periods[7:] == [DIRECTORY_PERIOD, 2 * DIRECTORY_PERIOD]  # a peer moved: soon again


def test_pending_commands_go_again_at_once_when_contact_returns() -> None:
    outbox: Outbox[str] = Outbox(first_retry=0.25, max_retry=5.0)
    outbox.robot_numbering(0, now=0.0)
    outbox.enqueue("upload")
    sent = [now for now in (0.0, 0.25, 0.75, 1.75, 3.75, 7.75, 12.75) if outbox.due(now)]
    assert sent == [0.0, 0.25, 0.75, 1.75, 3.75, 7.75, 12.75]  # backed off to 5 s
    assert not outbox.due(14.0)
    outbox.contact_returned(14.0)
    assert [item.payload for item in outbox.due(14.0)] == ["upload"]
    assert not outbox.due(14.2) and outbox.due(14.25)  # the backoff starts again
    assert outbox.pending()[0].attempts == 9  # every transmission still counts
