"""The last-link marks rviz draws (rosmc_rviz_markers/core/coverage.py)."""

from __future__ import annotations

from rosmc_rviz_markers.core.coverage import OLD_AFTER, last_links
from rosmc_server.core.robots.radio_map import RadioMap, Reading


def test_a_robot_in_contact_has_an_unlabelled_mark_and_one_out_of_contact_a_label() -> None:
    radio = RadioMap()
    now = 100.0
    radio.add(Reading("rover", 1.0, 2.0, -55.0, True, now - 8.0))  # stands still, link up
    radio.add(Reading("drone", 8.0, 9.0, -72.0, True, now - 26.0))  # out of contact since
    marks = {mark.agent: mark for mark in last_links(radio, now, frozenset({"rover"}))}
    assert (marks["rover"].x, marks["rover"].y, marks["rover"].label) == (1.0, 2.0, "")
    assert not marks["rover"].old
    assert marks["drone"].label == "drone last link: -72 dBm 26 s ago" and marks["drone"].old


def test_the_label_appears_when_the_link_goes_down() -> None:
    radio = RadioMap()
    radio.add(Reading("rover", 1.0, 2.0, -55.0, True, 0.0))
    assert [m.label for m in last_links(radio, 5.0, frozenset({"rover"}))] == [""]
    later = last_links(radio, 5.0)
    assert [m.label for m in later] == ["rover last link: -55 dBm 5 s ago"]
    assert not later[0].old and last_links(radio, OLD_AFTER + 1.0)[0].old
