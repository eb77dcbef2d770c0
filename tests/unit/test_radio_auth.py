"""Signed radio datagrams: forged, replayed, truncated, reordered and wrong-key ones are refused."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from rosmc_server.core import RosmcError
from rosmc_server.core.errors import RadioKeyError
from rosmc_server.core.robots.drop_log import DropLog
from rosmc_server.core.robots.radio import MAX_DATAGRAM, DatagramKind
from rosmc_server.core.robots.radio_auth import (
    MAGIC,
    OVERHEAD,
    SIGNATURE_BYTES,
    DatagramRefused,
    Opener,
    Refusal,
    Sealer,
    stamp_of,
)
from rosmc_server.core.robots.radio_key import (
    KEY_BYTES,
    RadioKey,
    default_key_path,
    load_key,
    make_key,
    obtain_key,
)

TEAM = RadioKey(bytes(range(32)), Path("team.key"))
OTHER = RadioKey(bytes(range(1, 33)), Path("other.key"))


def sealer(name: str = "r2", key: RadioKey = TEAM, at: float = 1_700_000_000.0) -> Sealer:
    """A sender whose clock stands still at ``at`` (its stamps grow all the same)."""
    return Sealer(key, name, clock=lambda: at)


def refusal(opener: Opener, data: bytes) -> Refusal:
    with pytest.raises(DatagramRefused) as caught:
        opener.open(data)
    return caught.value.refusal


def test_a_signed_datagram_opens_to_its_sender_kind_and_payload() -> None:
    r2 = sealer()
    r1 = Opener(TEAM, "r1")
    for kind in DatagramKind:
        opened = r1.open(r2.seal(kind, b"payload"))
        assert (opened.kind, opened.sender, opened.link_id, opened.payload) == (
            kind,
            "r2",
            0,
            b"payload",
        )
    assert len(r2.seal(DatagramKind.BEACON)) == OVERHEAD + len("r2")


def test_stamps_grow_even_when_the_clock_stands_still_or_goes_back() -> None:
    at = 1_700_000_000.0
    readings = iter([at + 100.0, at + 100.0, at + 50.0, at + 200.0])
    r2 = Sealer(TEAM, "r2", clock=lambda: next(readings))
    r1 = Opener(TEAM, "r1")
    stamps = [r1.open(r2.seal(DatagramKind.BEACON)).stamp for _ in range(4)]
    assert stamps == sorted(set(stamps))
    assert stamps[-1] == stamp_of(at + 200.0)


def test_forged_datagrams_are_refused_and_change_nothing() -> None:
    r1 = Opener(TEAM, "r1")
    genuine = sealer().seal(DatagramKind.BARRIER_SIGNAL, b"RELEASED")
    flipped = bytearray(genuine)
    flipped[OVERHEAD - SIGNATURE_BYTES + 2] ^= 0x01  # the payload, signature unchanged
    assert refusal(r1, bytes(flipped)) is Refusal.FORGED
    wrong_key = sealer(key=OTHER).seal(DatagramKind.BARRIER_SIGNAL, b"RELEASED")
    assert refusal(r1, wrong_key) is Refusal.FORGED
    unsigned = b"RMC\x01\x02" + b"serialized BarrierSignal"  # the old, unsigned framing
    assert refusal(r1, unsigned) is Refusal.MALFORMED
    zeroed = genuine[:-SIGNATURE_BYTES] + bytes(SIGNATURE_BYTES)
    assert refusal(r1, zeroed) is Refusal.FORGED
    # None of them moved r2's window: the genuine datagram still opens.
    assert r1.open(genuine).payload == b"RELEASED"


@pytest.mark.parametrize("cut", [1, 4, SIGNATURE_BYTES, 20, 30])
def test_truncated_datagrams_are_refused(cut: int) -> None:
    r1 = Opener(TEAM, "r1")
    genuine = sealer().seal(DatagramKind.BARRIER_SIGNAL, b"0123456789")
    assert refusal(r1, genuine[:-cut]) in (Refusal.FORGED, Refusal.MALFORMED)
    assert r1.open(genuine).payload == b"0123456789"


@pytest.mark.parametrize("junk", [b"", b"junk", MAGIC, MAGIC + bytes(40), os.urandom(200)])
def test_junk_is_malformed_or_forged(junk: bytes) -> None:
    assert refusal(Opener(TEAM, "r1"), junk) in (Refusal.MALFORMED, Refusal.FORGED)


def test_replayed_and_reordered_datagrams_are_refused() -> None:
    r2 = Sealer(TEAM, "r2", clock=lambda: 1_700_000_000.0)
    r1 = Opener(TEAM, "r1")
    first, second, third = (r2.seal(DatagramKind.BARRIER_SIGNAL, bytes([n])) for n in range(3))
    r1.open(first)
    r1.open(third)
    assert refusal(r1, second) is Refusal.REPLAYED  # overtaken by a newer one
    assert refusal(r1, third) is Refusal.REPLAYED  # the same again
    assert refusal(r1, first) is Refusal.REPLAYED


def test_the_window_is_kept_per_sender_and_link() -> None:
    r1 = Opener(TEAM, "r1")
    ground = sealer("ground", at=1_000_000_000.0)  # another host's clock, years behind
    r2 = sealer("r2", at=1_800_000_000.0)
    r2_second = Sealer(TEAM, "r2", link_id=1, clock=lambda: 1_000_000_000.0)
    assert r1.open(r2.seal(DatagramKind.BEACON)).sender == "r2"
    assert r1.open(ground.seal(DatagramKind.BEACON)).sender == "ground"
    assert r1.open(r2_second.seal(DatagramKind.BEACON)).link_id == 1


def test_a_restarted_sender_is_heard_at_once_a_replay_of_its_last_run_is_not() -> None:
    r1 = Opener(TEAM, "r1")
    old_run = sealer("r2", at=1_700_000_000.0)
    recorded = old_run.seal(DatagramKind.BARRIER_SIGNAL, b"RELEASED")
    r1.open(recorded)
    new_run = sealer("r2", at=1_700_000_060.0)  # restarted a minute later: a new Sealer
    r1.open(new_run.seal(DatagramKind.BEACON))
    assert refusal(r1, recorded) is Refusal.REPLAYED


def test_a_datagram_reflected_back_to_its_sender_is_refused() -> None:
    r1 = sealer("r1")
    assert refusal(Opener(TEAM, "r1"), r1.seal(DatagramKind.BEACON)) is Refusal.REFLECTED


def test_a_datagram_too_big_for_one_frame_is_refused_before_it_is_sent() -> None:
    with pytest.raises(RosmcError, match=f"at most {MAX_DATAGRAM} bytes"):
        sealer().seal(DatagramKind.BARRIER_SIGNAL, bytes(MAX_DATAGRAM))
    with pytest.raises(RosmcError, match="1 to 64 bytes"):
        Sealer(TEAM, "")


def test_a_key_is_made_private_and_reads_back(tmp_path: Path) -> None:
    path = tmp_path / "deep" / "radio.key"
    made = make_key(path)
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    assert len(made.secret) == KEY_BYTES
    loaded = load_key(path)
    assert loaded.secret == made.secret and loaded.fingerprint == made.fingerprint
    assert made.secret.hex() not in repr(made)
    with pytest.raises(RadioKeyError, match=r"already exists.*rosmc key new --force"):
        make_key(path)
    assert load_key(path).secret == made.secret  # not overwritten
    assert make_key(path, replace=True).secret != made.secret  # rotation
    assert [p.name for p in path.parent.iterdir()] == ["radio.key"]  # no temporary left


def test_unusable_keys_are_refused_in_one_sentence_naming_the_file_and_fix(tmp_path: Path) -> None:
    missing = tmp_path / "none.key"
    with pytest.raises(RadioKeyError, match=f"no radio key at {missing}.*rosmc key new {missing}"):
        load_key(missing)
    shared = tmp_path / "shared.key"
    make_key(shared)
    shared.chmod(0o640)
    with pytest.raises(RadioKeyError, match=r"open to other users \(mode 0640\).*chmod 600"):
        load_key(shared)
    garbled = tmp_path / "garbled.key"
    garbled.write_text("rosmc-radio-key 1\nnot hex\n")
    garbled.chmod(0o600)
    with pytest.raises(RadioKeyError, match="is not a rosmc radio key"):
        load_key(garbled)
    with pytest.raises(RadioKeyError, match="not a regular file"):
        load_key(tmp_path)
    for error in (missing, shared, garbled):
        with pytest.raises(RadioKeyError) as caught:
            load_key(error)
        assert "\n" not in str(caught.value)


def test_nodes_make_the_default_key_but_never_one_they_were_given(tmp_path: Path) -> None:
    environ = {"ROS_HOME": str(tmp_path / "home")}
    assert default_key_path(environ) == tmp_path / "home" / "rosmc" / "radio.key"
    first, made = obtain_key(None, environ)
    again, made_again = obtain_key(None, environ)
    assert made and not made_again and first.secret == again.secret
    given = tmp_path / "given.key"
    with pytest.raises(RadioKeyError, match="no radio key"):
        obtain_key(given, environ)
    assert not given.exists()


def test_drops_are_counted_every_time_and_logged_at_a_limited_rate() -> None:
    log = DropLog("radio datagram", period=30.0)
    lines = [log.drop("it is forged", f"from port {n}", now=n * 0.001) for n in range(5000)]
    warnings = [line for line in lines if line is not None]
    assert log.total == log.count("it is forged") == 5000
    assert len(warnings) == 1 and "more like it are counted" in warnings[0]
    later = log.drop("it is forged", "from port 9", now=31.0)
    assert later is not None
    assert later.startswith("dropped 5000 more radio datagrams (5001 in all)"), later
    assert log.drop("it is replayed", "from port 9", now=31.0) is not None  # its own reason
