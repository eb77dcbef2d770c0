"""The lost-link policy picker: what a robot does when it stops hearing the ground.

:class:`PolicyDialog` offers the choices of :class:`~rosmc_server.core.LostLinkPolicy`:
keep going, hold after N seconds, run a safe skill (one of that robot's skills) after N
seconds and then hold, or return to where the robot last had a link (with a skill that
goes to a pose) and then hold; the seconds count either from the link's loss or only
while the robot is idle too. It shows the policy in force (perhaps the library's
default) and only builds the typed policy; the robot's column sends it.
"""

from __future__ import annotations

from collections.abc import Sequence

from python_qt_binding.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QWidget,
)

from rosmc_server.core import (
    InvalidRequest,
    LostLinkKind,
    LostLinkPolicy,
    LostLinkTrigger,
    PolicyInForce,
)
from rosmc_server.core.skills.policy import DEFAULT_AFTER

KIND_WORDS = {
    LostLinkKind.CONTINUE: "keep going",
    LostLinkKind.HOLD: "hold (pause) after a while",
    LostLinkKind.SAFE_SKILL: "run a safe skill after a while, then hold",
    LostLinkKind.RETURN_TO_LINK: "return to where it last had a link, then hold",
}
RETURN_SKILL = "navigate_to"  # offered first for a return, if the robot has it


class PolicyDialog(QDialog):  # type: ignore[misc]
    """Choose ``agent``'s lost-link policy among ``skills`` (the robot's skills).

    Args:
        agent: The robot.
        skills: The skills the robot can run as its safe skill.
        preferred: The safe skill offered first if the robot has it.
        in_force: The policy the robot reports in force (None if unknown).
        pending: A policy chosen and waiting for contact with the robot (None if none).
        reported: False: ``in_force`` is the library's default, which the server sends the
            robot, not reported by the robot yet.

    It opens on the pending policy, else on the policy in force (never on a choice the
    operator did not make).
    """

    def __init__(
        self,
        agent: str,
        skills: Sequence[str],
        preferred: str = "return_to_lander",
        parent: QWidget | None = None,
        in_force: PolicyInForce | None = None,
        pending: LostLinkPolicy | None = None,
        reported: bool = True,
    ) -> None:
        super().__init__(parent)
        self.setWindowTitle(f"{agent}: when the link is lost")
        self.kind_combo = QComboBox()
        self.kind_combo.setObjectName("policy_kind")
        for kind, words in KIND_WORDS.items():
            self.kind_combo.addItem(words, kind)
        self.after_spin = QDoubleSpinBox()
        self.after_spin.setObjectName("policy_after")
        self.after_spin.setRange(1.0, 86400.0)
        self.after_spin.setDecimals(0)
        self.after_spin.setSuffix(" s without the ground")
        self.after_spin.setValue(DEFAULT_AFTER)
        self.skill_combo = QComboBox()
        self.skill_combo.setObjectName("policy_skill")
        names = sorted(skills)
        self.skill_combo.addItems(names)
        self._preferred = preferred
        if preferred in names:
            self.skill_combo.setCurrentIndex(names.index(preferred))
        self.idle_check = QCheckBox("count only while the robot has nothing left to do")
        self.idle_check.setObjectName("policy_idle")
        self.in_force = QLabel(f"In force: {in_force_words(in_force, reported)}")
        self.in_force.setObjectName("policy_in_force")
        self.in_force.setWordWrap(True)
        self.pending = QLabel(
            f"Waiting for contact: {pending.describe()} (sent, not on the robot yet)"
            if pending is not None
            else ""
        )
        self.pending.setObjectName("policy_pending")
        self.pending.setWordWrap(True)
        self.pending.setStyleSheet("QLabel { color:#8a5a00; }")
        self.pending.setVisible(pending is not None)
        self.problem = QLabel("")
        self.problem.setStyleSheet("QLabel { color:#b00020; }")
        self.problem.setWordWrap(True)
        self.buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        form = QFormLayout(self)
        form.addRow(QLabel(f"What should <b>{agent}</b> do when it stops hearing the ground?"))
        form.addRow(self.in_force)
        form.addRow(self.pending)
        form.addRow("Then", self.kind_combo)
        form.addRow("After", self.after_spin)
        form.addRow("", self.idle_check)
        form.addRow("Skill", self.skill_combo)
        form.addRow(self.problem)
        form.addRow(self.buttons)
        self.buttons.accepted.connect(self._on_buttons_accepted)
        self.buttons.rejected.connect(self.reject)
        self.kind_combo.currentIndexChanged.connect(self._on_kind_combo_current_index_changed)
        self._on_kind_combo_current_index_changed(0)
        shown = pending or (in_force.policy if in_force is not None else None)
        if shown is not None:
            self.show_policy(shown)

    def show_policy(self, policy: LostLinkPolicy) -> None:
        """Fill the fields with ``policy`` (the one in force, or the one waiting)."""
        self.set_kind(policy.kind)
        if policy.kind is LostLinkKind.CONTINUE:
            return
        self.after_spin.setValue(policy.after)
        self.idle_check.setChecked(policy.when is LostLinkTrigger.IDLE)
        index = self.skill_combo.findText(policy.skill)
        if policy.kind.runs_skill and index >= 0:
            self.skill_combo.setCurrentIndex(index)

    def set_kind(self, kind: LostLinkKind) -> None:
        """Pick ``kind`` (as the operator would in the first list)."""
        self.kind_combo.setCurrentIndex(self.kind_combo.findData(kind))

    def policy(self) -> LostLinkPolicy:
        """The policy chosen (InvalidRequest with a sentence if it cannot be one)."""
        kind = LostLinkKind(self.kind_combo.currentData())
        if kind is LostLinkKind.CONTINUE:
            return LostLinkPolicy()
        when = LostLinkTrigger.IDLE if self.idle_check.isChecked() else LostLinkTrigger.SILENT
        if kind is LostLinkKind.HOLD:
            return LostLinkPolicy(kind, self.after_spin.value(), when=when)
        skill = self.skill_combo.currentText()
        if not skill:
            raise InvalidRequest("this robot has no skill to run as its safe skill")
        return LostLinkPolicy(kind, self.after_spin.value(), skill, when=when)

    def _on_kind_combo_current_index_changed(self, _index: int) -> None:
        kind = LostLinkKind(self.kind_combo.currentData())
        self.after_spin.setEnabled(kind is not LostLinkKind.CONTINUE)
        self.idle_check.setEnabled(kind is not LostLinkKind.CONTINUE)
        self.skill_combo.setEnabled(kind.runs_skill)
        # A return goes to a pose: offer the skill that does, the safe skill otherwise.
        wanted = RETURN_SKILL if kind is LostLinkKind.RETURN_TO_LINK else self._preferred
        index = self.skill_combo.findText(wanted)
        if kind.runs_skill and index >= 0:
            self.skill_combo.setCurrentIndex(index)
        if kind is LostLinkKind.RETURN_TO_LINK:
            self.idle_check.setChecked(True)

    def _on_buttons_accepted(self) -> None:
        try:
            self.policy()
        except InvalidRequest as error:
            self.problem.setText(f"{error}.")
            return
        self.accept()


def in_force_words(in_force: PolicyInForce | None, reported: bool = True) -> str:
    """The policy in force for the dialog's first line (``reported``: see PolicyDialog)."""
    if in_force is None:
        return "not reported yet"
    if reported:
        return in_force.describe()
    return f"{in_force.policy.describe()} (library default, not reported yet)"


def ask_policy(
    agent: str,
    skills: Sequence[str],
    parent: QWidget | None = None,
    in_force: PolicyInForce | None = None,
    pending: LostLinkPolicy | None = None,
    reported: bool = True,
) -> LostLinkPolicy | None:
    """Show the dialog; the chosen policy, or None if the operator cancels."""
    dialog = PolicyDialog(
        agent, skills, parent=parent, in_force=in_force, pending=pending, reported=reported
    )
    if dialog.exec_() != QDialog.Accepted:
        return None
    return dialog.policy()
