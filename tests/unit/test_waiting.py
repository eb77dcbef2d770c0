"""Commands for a robot out of contact wait, collapse, leave once (core/robots/waiting.py)."""

from __future__ import annotations

from dataclasses import dataclass, field

from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.robots.link import InboundSequence, LinkStatus, Outbox
from rosmc_server.core.robots.waiting import (
    MAX_WAITING,
    collapse,
    duration_text,
    queued_note,
    queued_notes,
    refusal,
    room_refusal,
    waiting_text,
    waiting_work,
)

TIMEOUT = 3.0


@dataclass
class Skill:
    id: str


@dataclass
class Cmd:
    """The fields of ``rosmc/RobotCommand`` the waiting rules read."""

    type: int
    skills: list[Skill] = field(default_factory=list)
    skill_ids: list[str] = field(default_factory=list)
    argument: str = ""


def command(kind: CommandKind, skills: tuple[str, ...] = (), ids: tuple[str, ...] = ()) -> Cmd:
    return Cmd(int(kind), [Skill(s) for s in skills], list(ids))


def queue(outbox: Outbox[Cmd], msg: Cmd, now: float = 0.0) -> list[Cmd]:
    """Queue ``msg`` as the ground link does; returns the commands it withdrew."""
    result = collapse(outbox, msg)
    if result.kept is not None:
        outbox.enqueue(result.kept, now)
    return [item.payload for item in result.withdrawn]


def kinds(outbox: Outbox[Cmd]) -> list[tuple[CommandKind, list[str]]]:
    return [
        (CommandKind(i.payload.type), [s.id for s in i.payload.skills] + i.payload.skill_ids)
        for i in outbox.pending()
    ]


def lost_outbox() -> Outbox[Cmd]:
    """An outbox whose robot was heard at t=0 (numbering 0) and is silent since."""
    outbox: Outbox[Cmd] = Outbox(timeout=TIMEOUT)
    outbox.robot_numbering(0, now=0.0)
    return outbox


class Robot:
    """The robot's end: executes each number once, in order, and acknowledges it."""

    def __init__(self) -> None:
        self.inbound = InboundSequence()
        self.executed: list[Cmd] = []

    def receive(self, outbox: Outbox[Cmd], now: float) -> None:
        for item in outbox.due(now):
            if self.inbound.classify(item.seq).value == "next":
                self.inbound.accept(item.seq)
                self.executed.append(item.payload)
        for item in list(outbox.pending()):
            if item.seq and item.seq <= self.inbound.last:
                outbox.acknowledge(item.seq, now)


def test_while_the_link_is_down_new_commands_wait_unnumbered_and_old_ones_retransmit() -> None:
    outbox = lost_outbox()
    sent = outbox.enqueue(command(CommandKind.START), now=1.0)
    assert [i.seq for i in outbox.due(1.0)] == [1]  # the link is up: it leaves at once
    later = 10.0
    assert outbox.status(later) is LinkStatus.DOWN
    queue(outbox, command(CommandKind.UPLOAD, ("a",)), now=later)
    due = outbox.due(later)
    assert [i.payload for i in due] == [sent.payload], "only the numbered one goes again"
    assert [i.seq for i in outbox.unsent()] == [0], "the new command waits unnumbered"
    assert outbox.unsent()[0].held
    report = outbox.report(later + 120.0)
    assert (report.waiting, report.waiting_for) == (2, later + 120.0 - 1.0)


def test_what_waited_leaves_in_order_exactly_once_when_the_robot_is_heard() -> None:
    outbox = lost_outbox()
    robot = Robot()
    now = 10.0  # out of contact
    for kind, skills in ((CommandKind.UPLOAD, ("a",)), (CommandKind.UPLOAD, ("b",))):
        queue(outbox, command(kind, skills), now)
    queue(outbox, command(CommandKind.START), now)
    for step in range(5):
        robot.receive(outbox, now + step)
    assert robot.executed == [], "nothing leaves while the robot cannot be heard"
    outbox.heard(now + 5)
    for step in range(5, 30):  # duplicates and retransmissions on the way
        robot.receive(outbox, now + step)
        outbox.heard(now + step)
    executed = [(CommandKind(c.type), [s.id for s in c.skills]) for c in robot.executed]
    assert executed == [
        (CommandKind.UPLOAD, ["a"]),
        (CommandKind.UPLOAD, ["b"]),
        (CommandKind.START, []),
    ]
    assert outbox.pending() == () and outbox.report(now + 30).waiting == 0


def test_answers_to_held_commands_are_taken_in_order_when_the_first_one_is_lost() -> None:
    # The radio returns: the three held uploads leave together and the robot executes and
    # answers each. The first answer is lost (the ground was reconnecting its topics).
    # Taking the second before the first confirmed an upload before the one it follows,
    # and it stayed "uploading" for good.
    outbox = lost_outbox()
    now = 10.0  # out of contact
    for skill in ("a", "b", "c"):
        queue(outbox, command(CommandKind.UPLOAD, (skill,)), now)
    outbox.heard(now + 60.0)
    first, second, third = outbox.due(now + 60.0)
    assert [first.seq, second.seq, third.seq] == [1, 2, 3]
    later = now + 60.1  # the answer to 1 never came; those to 2 and 3 do
    assert outbox.acknowledge(second.seq, later) is None, "an answer before an earlier one"
    assert outbox.acknowledge(third.seq, later) is None
    assert [i.seq for i in outbox.due(later)] == [1, 2, 3], "all asked again at once"
    taken = [outbox.acknowledge(seq, later + 0.1) for seq in (1, 2, 3)]  # answered again
    assert [(item.payload.skills[0].id if item else None) for item in taken] == ["a", "b", "c"]
    assert outbox.pending() == ()


def test_a_take_back_cancels_what_a_waiting_send_would_have_brought() -> None:
    outbox = lost_outbox()
    queue(outbox, command(CommandKind.UPLOAD, ("a", "b", "c")), 10.0)
    queue(outbox, command(CommandKind.UNSYNC, ids=("b", "c", "x")), 10.0)
    assert kinds(outbox) == [(CommandKind.UPLOAD, ["a"]), (CommandKind.UNSYNC, ["x"])]
    withdrawn = queue(outbox, command(CommandKind.UNSYNC, ids=("a",)), 10.0)
    assert kinds(outbox) == [(CommandKind.UNSYNC, ["x"])]
    assert [CommandKind(c.type) for c in withdrawn] == [CommandKind.UPLOAD]


def test_a_second_policy_or_barrier_set_replaces_the_waiting_one() -> None:
    outbox = lost_outbox()
    queue(outbox, Cmd(int(CommandKind.SET_OPTIONS), argument="hold"), 10.0)
    queue(outbox, command(CommandKind.BARRIERS), 10.0)
    queue(outbox, Cmd(int(CommandKind.SET_OPTIONS), argument="return"), 10.0)
    queue(outbox, command(CommandKind.BARRIERS), 10.0)
    assert [(CommandKind(i.payload.type), i.payload.argument) for i in outbox.pending()] == [
        (CommandKind.SET_OPTIONS, "return"),
        (CommandKind.BARRIERS, ""),
    ]


def test_controls_repeat_once_cancel_in_pairs_and_stop_supersedes_what_waits_before_it() -> None:
    outbox = lost_outbox()
    queue(outbox, command(CommandKind.START), 10.0)
    queue(outbox, command(CommandKind.START), 10.0)
    assert kinds(outbox) == [(CommandKind.START, [])]
    queue(outbox, command(CommandKind.PAUSE), 10.0)
    queue(outbox, command(CommandKind.RESUME), 10.0)
    assert kinds(outbox) == [(CommandKind.START, [])]
    queue(outbox, command(CommandKind.PAUSE), 10.0)
    queue(outbox, command(CommandKind.STOP), 10.0)
    queue(outbox, command(CommandKind.STOP), 10.0)
    assert kinds(outbox) == [(CommandKind.STOP, [])], "start then stop: only the stop is left"


def test_commands_already_transmitted_are_never_touched() -> None:
    outbox = lost_outbox()
    queue(outbox, command(CommandKind.UPLOAD, ("a",)))
    queue(outbox, command(CommandKind.START))
    assert len(outbox.due(0.0)) == 2
    queue(outbox, command(CommandKind.UNSYNC, ids=("a",)))
    queue(outbox, command(CommandKind.STOP))
    assert kinds(outbox) == [
        (CommandKind.UPLOAD, ["a"]),
        (CommandKind.START, []),
        (CommandKind.UNSYNC, ["a"]),
        (CommandKind.STOP, []),
    ]


def test_the_bound_is_a_core_rule_by_command_kind() -> None:
    """The services only call it: work is bounded; controls, policies and a take-back that
    cancels an upload (kind None) collapse with or withdraw what waits, never refused."""
    full = MAX_WAITING
    for kind in (CommandKind.UPLOAD, CommandKind.UNSYNC, CommandKind.RETRY, CommandKind.SKIP):
        assert room_refusal("rover", kind, full - 1) == ""
        assert room_refusal("rover", kind, full) == refusal("rover", full)
    for kind in (CommandKind.START, CommandKind.PAUSE, CommandKind.STOP, CommandKind.SET_OPTIONS):
        assert room_refusal("rover", kind, full) == ""
    assert room_refusal("rover", None, full) == ""


def test_the_bound_is_refused_with_one_sentence() -> None:
    assert refusal("rover", MAX_WAITING - 1) == ""
    sentence = refusal("rover", MAX_WAITING)
    assert sentence == (
        f"rover already has {MAX_WAITING} uploads and take-backs waiting for contact; take "
        "some back or wait until the robot is heard (stop, pause, resume and policies still go)"
    )
    assert sentence.count(".") == 0 and "\n" not in sentence


def test_waiting_reads_with_its_age() -> None:
    assert waiting_text(0, -1.0) == ""
    assert waiting_text(1, 42.0) == "1 command waiting for contact 42 s"
    assert waiting_text(2, 150.0) == "2 commands waiting for contact 2 min"
    assert duration_text(7300.0) == "2 h"
    assert queued_note("rover", False, 95.0) == (
        "queued for rover: out of contact (last heard 1 min ago); "
        "it goes out when the robot is heard again"
    )
    assert queued_note("rover", True, -1.0).startswith("queued for rover: not heard since")


def test_robots_never_heard_share_one_note_and_lost_ones_keep_their_age() -> None:
    notes = queued_notes([("a", True, -1.0), ("b", False, 75.0), ("c", True, -1.0)])
    assert notes == [
        "queued for a, c: not heard since the server started; "
        "it goes out when the robot first reports",
        "queued for b: out of contact (last heard 1 min ago); "
        "it goes out when the robot is heard again",
    ]


def test_at_the_bound_controls_and_policies_still_go_and_collapse_the_latest_winning() -> None:
    outbox = lost_outbox()
    for n in range(MAX_WAITING):
        queue(outbox, command(CommandKind.UPLOAD, (f"s{n}",)), 10.0)
    assert waiting_work(outbox) == MAX_WAITING and refusal("rover", waiting_work(outbox))
    # Safety commands and policy changes, many times over: none counts against the bound,
    # and what waits of them stays small.
    for _ in range(20):
        for kind in (CommandKind.PAUSE, CommandKind.RESUME, CommandKind.PAUSE):
            queue(outbox, command(kind), 10.0)
        queue(outbox, Cmd(int(CommandKind.SET_OPTIONS), argument="hold"), 10.0)
        queue(outbox, Cmd(int(CommandKind.SET_OPTIONS), argument="return"), 10.0)
    assert waiting_work(outbox) == MAX_WAITING
    extra = [(CommandKind(i.payload.type), i.payload.argument) for i in outbox.unsent()][
        MAX_WAITING:
    ]
    assert extra == [(CommandKind.PAUSE, ""), (CommandKind.SET_OPTIONS, "return")]
    queue(outbox, command(CommandKind.STOP), 10.0)
    queue(outbox, command(CommandKind.STOP), 10.0)
    extra = [CommandKind(i.payload.type) for i in outbox.unsent()][MAX_WAITING:]
    assert extra == [CommandKind.SET_OPTIONS, CommandKind.STOP], "stop took the pause back"
    assert len(outbox.unsent()) == MAX_WAITING + 2


def test_a_resume_cancels_a_waiting_pause_whatever_came_between() -> None:
    outbox = lost_outbox()
    queue(outbox, command(CommandKind.PAUSE), 10.0)
    queue(outbox, command(CommandKind.UPLOAD, ("a",)), 10.0)
    queue(outbox, Cmd(int(CommandKind.SET_OPTIONS), argument="hold"), 10.0)
    withdrawn = queue(outbox, command(CommandKind.RESUME), 10.0)
    assert [CommandKind(c.type) for c in withdrawn] == [CommandKind.PAUSE]
    assert kinds(outbox) == [(CommandKind.UPLOAD, ["a"]), (CommandKind.SET_OPTIONS, [])]


def test_a_start_after_new_uploads_is_kept_a_start_with_nothing_new_is_a_repeat() -> None:
    outbox = lost_outbox()
    queue(outbox, command(CommandKind.START), 10.0)
    queue(outbox, command(CommandKind.UPLOAD, ("a",)), 10.0)
    queue(outbox, command(CommandKind.START), 10.0)
    queue(outbox, command(CommandKind.START), 10.0)
    assert kinds(outbox) == [
        (CommandKind.START, []),
        (CommandKind.UPLOAD, ["a"]),
        (CommandKind.START, []),
    ]
    queue(outbox, command(CommandKind.STOP), 10.0)
    assert kinds(outbox) == [(CommandKind.UPLOAD, ["a"]), (CommandKind.STOP, [])]
