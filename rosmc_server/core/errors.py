"""The one exception family of ROSMC.

Every rejection the mission core makes is a :class:`RosmcError` whose message
is one sentence an operator can act on. The subclasses say *why* a request
failed, so adapters can map them to an error code without parsing text.
"""


class RosmcError(Exception):
    """Root of every error ROSMC raises on purpose.

    A message stays on one line: names quoted from a request (ids, agents,
    markers) may hold line breaks, which are written as escapes instead.
    """

    def __init__(self, *args: object) -> None:
        if len(args) == 1 and isinstance(args[0], str):
            args = (_one_line(args[0]),)
        super().__init__(*args)


def _one_line(message: str) -> str:
    return "".join(ch if ch.isprintable() else ascii(ch)[1:-1] for ch in message)


class InvalidRequest(RosmcError):
    """A request is malformed: empty, of the wrong type, or out of range."""


class NotFound(RosmcError):
    """A request names an agent, skill, barrier or marker that does not exist."""


class RuleViolation(RosmcError):
    """A well-formed request that the mission rules forbid in the current state."""


class StaleRevision(RosmcError):
    """A request was made against a revision that another operator's change superseded."""

    def __init__(self, base_revision: int, current_revision: int) -> None:
        again = "run 'rosmc status' (or look at the command GUI) to see it, then try again"
        if base_revision > current_revision:
            problem = (
                f"revision {base_revision} is ahead of the mission, which is at revision "
                f"{current_revision}: the request was made against another mission or server"
            )
        else:
            problem = (
                f"the mission changed since revision {base_revision} "
                f"(it is now at revision {current_revision})"
            )
        super().__init__(f"{problem}; {again}")
        self.base_revision = base_revision
        self.current_revision = current_revision


class Unavailable(RosmcError):
    """The request cannot be served now (too much waits for a robot out of contact, or the
    server is shutting down); out of contact alone is never the reason."""


class StorageFull(Unavailable):
    """The journal's disk lacks the room a change needs: refused until space returns."""

    def __init__(self, free_bytes: int) -> None:
        super().__init__(f"the journal's disk is full: {free_bytes} bytes free")
        self.free_bytes = free_bytes


class ServerUnavailable(RosmcError):
    """The mission server (or the ROS master) did not answer in time: a client's error."""


class NotPermitted(RosmcError):
    """The calling node is not on the mission server's operator allow-list."""


class LibraryError(RosmcError):
    """A skill library file is malformed; the message names the file and the key."""


class SkillSetupError(RosmcError):
    """A robot's skill implementations or bindings do not fit its library: the executor
    refuses to start, and the message says which skill and why."""


class MissionFileError(RosmcError):
    """A mission file cannot be loaded; the message names the file and the problem."""


class RadioKeyError(RosmcError):
    """The deployment's radio key file is missing, malformed or readable by others: the
    node refuses to start, and the message names the file and the command that fixes it."""
