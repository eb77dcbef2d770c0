"""The parameter panel: everything about the selected skill, editable while it is planned.

Shows id, robot, skill, label, status, attempt, status text, timeout and retries, then
one typed editor per parameter (with its unit and description) and a marker picker for
parameters a task marker can fill. Each change is checked against the library's spec
before it is sent; a value that cannot be sent is tinted and explained. Everything is
read-only unless the skill is in the editable blueprint.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from python_qt_binding.QtCore import Qt, Signal
from python_qt_binding.QtWidgets import (
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QLineEdit,
    QScrollArea,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from rosmc_server.core import InvalidRequest, RosmcError, SkillInstance, SkillSpec
from rosmc_server.core.rules.editing import check_retries, check_timeout
from rosmc_server.core.validation import MAX_RETRIES

from ..core.mission_view import MissionView
from ..core.requests import Answer
from .param_editors import INVALID_STYLE, Editor, make_editor, wide_range
from .place_picker import PlacePicker
from .place_rows import PlaceRows


class ParameterPanel(QScrollArea):  # type: ignore[misc]
    """Details and parameters of one skill."""

    edit_requested = Signal(str, dict)  # skill id, edit_skill keyword arguments
    rename_marker_requested = Signal(str, str)  # old name, new name
    problem = Signal(str)  # a sentence for the message area

    def __init__(self, view: MissionView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._view = view
        self.skill: SkillInstance | None = None
        self.editors: dict[str, Editor] = {}
        self.places = PlaceRows(view)  # the Place pickers and "Drive there first"
        self.places.edit_requested.connect(self.edit_requested)
        self.places.rename_requested.connect(self.rename_marker_requested)
        self._shown: dict[str, object] = {}  # what each editor showed of the skill
        self._spec: SkillSpec | None = None
        self.setWidgetResizable(True)
        self.setMinimumWidth(320)
        body = QWidget()
        layout = QVBoxLayout(body)
        self.title = QLabel("<i>Select a skill to see its parameters.</i>")
        self.title.setWordWrap(True)
        layout.addWidget(self.title)
        details = QGroupBox("Skill")
        form = QFormLayout(details)
        self.facts: dict[str, QLabel] = {}
        for name in ("ID", "Robot", "Skill", "Status", "Attempt", "Status text"):
            label = QLabel("")
            label.setWordWrap(True)
            label.setTextInteractionFlags(Qt.TextSelectableByMouse)
            self.facts[name] = label
        self.label_edit = QLineEdit()
        self.label_edit.setObjectName("label_edit")
        self.timeout_spin = QDoubleSpinBox()
        self.timeout_spin.setObjectName("timeout_spin")
        self.timeout_spin.setSuffix(" s")
        self.timeout_spin.setToolTip("Seconds the skill may run; 0 s: no time limit")
        self.retries_spin = QSpinBox()
        self.retries_spin.setObjectName("retries_spin")
        self.retries_spin.setToolTip(f"Automatic retries after a failure: 0 to {MAX_RETRIES}")
        for spin in (self.timeout_spin, self.retries_spin):
            wide_range(spin)  # out-of-range input is refused with the range, not changed
            spin.setKeyboardTracking(False)
        for name in ("ID", "Robot", "Skill"):
            form.addRow(name, self.facts[name])
        form.addRow("Label", self.label_edit)
        for name in ("Status", "Attempt", "Status text"):
            form.addRow(name, self.facts[name])
        form.addRow("Time limit (0: none)", self.timeout_spin)
        form.addRow("Retries", self.retries_spin)
        layout.addWidget(details)
        self.params_box = QGroupBox("Parameters")
        self.params_form = QFormLayout(self.params_box)
        layout.addWidget(self.params_box)
        layout.addStretch(1)
        self.setWidget(body)
        self.label_edit.editingFinished.connect(self._on_label_edit_editing_finished)
        self.timeout_spin.editingFinished.connect(self._on_options_editing_finished)
        self.retries_spin.editingFinished.connect(self._on_options_editing_finished)
        self.show_skill(None)

    @property
    def pickers(self) -> dict[str, PlacePicker]:
        """The Place picker of each location parameter of the shown skill."""
        return self.places.pickers

    # -- showing ------------------------------------------------------------------------------
    @property
    def editable(self) -> bool:
        """The shown skill can be edited."""
        return self.skill is not None and self.skill.is_editable and not self._read_only

    _read_only = False

    def set_read_only(self, read_only: bool) -> None:
        """Follow a replay: nothing can be edited."""
        self._read_only = read_only
        self.show_skill(self.skill)

    def show_selection(self, skill_ids: list[str]) -> None:
        """Show the one selected skill (or say how many are selected)."""
        skills = self._view.skills(skill_ids)
        self.show_skill(skills[0] if len(skills) == 1 else None, len(skills))

    def show_skill(self, skill: SkillInstance | None, count: int = 1) -> None:
        """Show ``skill`` (None: nothing); editors are rebuilt only for another skill."""
        rebuild = skill is None or self.skill is None or skill.id != self.skill.id
        self.skill = skill
        if rebuild:  # a refusal's tint belongs to the skill it was typed for
            for widget in (self.label_edit, self.timeout_spin, self.retries_spin):
                widget.setStyleSheet("")
        if skill is None:
            self.title.setText(
                f"<i>{count} skills selected.</i>" if count > 1 else "<i>Select a skill.</i>"
            )
            self._clear_editors()
            for label in self.facts.values():
                label.setText("")
            self._show_options(None)
            self._enable(False)
            return
        self._spec = self._spec_of(skill)
        where = "planned (editable)" if skill.is_editable else "not editable (on the robot or done)"
        self.title.setText(f"<b>{skill.label or skill.skill}</b> on {skill.agent} — {where}")
        facts = {
            "ID": skill.id,
            "Robot": skill.agent,
            "Skill": skill.skill + (f" — {self._spec.description}" if self._spec else ""),
            "Status": self._view.status_text(skill),
            "Attempt": str(skill.attempt),
            "Status text": skill.status_text or "—",
        }
        for name, text in facts.items():
            self.facts[name].setText(text)
        self._show_options(skill)
        if rebuild:
            self._build_editors()
        self._fill_editors()
        self._enable(self.editable)

    def refresh(self, force: bool = False) -> None:
        """Show the newest version of the shown skill (after a live update)."""
        if self.skill is not None:
            newest = self._view.skill(self.skill.id)
            if force or newest is not self.skill:
                self.show_skill(newest)
            elif newest is not None:  # its robot's task changed: places and drive offer
                self.places.fill(newest, self.editable)

    def _show_options(self, skill: SkillInstance | None, force: bool = False) -> None:
        """The label, time limit and retries of ``skill``; blank for none (not the last
        skill's, which would pass for the selection's). A field being typed in is kept
        (unless ``force``)."""
        values = (None, None) if skill is None else (skill.timeout, skill.max_retries)
        if force or not self.label_edit.hasFocus():
            self.label_edit.setText("" if skill is None else skill.label)
        for spin, value in zip((self.timeout_spin, self.retries_spin), values, strict=True):
            if spin.hasFocus() and not force:
                continue
            # Blank: the box's minimum (far below any allowed value) shown as a space.
            spin.setSpecialValueText(" " if value is None else "")
            spin.setValue(spin.minimum() if value is None else value)

    def _spec_of(self, skill: SkillInstance) -> SkillSpec | None:
        library = self._view.library
        if library is None:
            return None
        try:
            return library.skill(skill.agent, skill.skill)
        except RosmcError:
            return None

    def _clear_editors(self) -> None:
        while self.params_form.rowCount():
            self.params_form.removeRow(0)
        self.editors = {}
        self.places.clear()

    def _build_editors(self) -> None:
        self._clear_editors()
        if self._spec is None:
            return
        for spec in self._spec.parameters:
            editor = make_editor(spec)
            editor.setObjectName(f"param_{spec.name}")
            editor.setToolTip(spec.description)
            editor.committed.connect(lambda n=spec.name: self._on_editor_committed(n))
            label = QLabel(spec.name + (f" ({spec.unit})" if spec.unit else ""))
            label.setToolTip(spec.description)
            self.params_form.addRow(label, editor)
            self.editors[spec.name] = editor
            if spec.marker_type is not None:
                self.places.add_picker(self.params_form, spec)
        self.places.add_drive_button(self.params_form)

    def _fill_editors(self, force: bool = False) -> None:
        """Show the skill's values (``force``: also in the editor being typed in)."""
        skill, spec = self.skill, self._spec
        if skill is None or spec is None:
            return
        for name, editor in self.editors.items():
            if name in skill.params and (force or not editor.isAncestorOf(editor.focusWidget())):
                editor.blockSignals(True)
                editor.set_value(skill.params[name])
                editor.mark_invalid(False)
                editor.blockSignals(False)
                self._shown[name] = _typed(editor)
        self.places.fill(skill, self.editable)

    def _enable(self, editable: bool) -> None:
        for widget in (self.label_edit, self.timeout_spin, self.retries_spin):
            widget.setEnabled(editable)
        for editor in self.editors.values():
            editor.set_read_only(not editable)
        self.places.enable(editable)

    # -- editing ------------------------------------------------------------------------------
    def _on_editor_committed(self, name: str) -> None:
        skill, spec = self.skill, self._spec
        editor = self.editors.get(name)
        if skill is None or spec is None or editor is None:
            return
        if not self.editable:
            if _typed(editor) != self._shown.get(name):  # typed in, not just left
                self._not_planned(skill, name)
                self._fill_editors(force=True)
            return
        try:
            value = spec.parameter(name).check(editor.value(), skill.skill)
        except InvalidRequest as error:
            editor.mark_invalid(True)
            allowed = getattr(editor, "allowed", "")  # a number's range, said with the refusal
            self.problem.emit(f"Not sent: {error}{f' (allowed: {allowed})' if allowed else ''}.")
            return
        editor.mark_invalid(False)
        if skill.params.get(name) != value or name in skill.bindings:
            self._send({"params": {name: _data(value)}})

    def _on_label_edit_editing_finished(self) -> None:
        skill = self.skill
        text = self.label_edit.text().strip()
        if skill is None or text == skill.label:
            return
        if not self.editable:
            self._not_planned(skill, "label")
            self.label_edit.setText(skill.label)
            return
        invalid = not text
        self.label_edit.setStyleSheet(INVALID_STYLE if invalid else "")
        if invalid:
            self.problem.emit(f"Not sent: a label cannot be empty (it stays '{skill.label}').")
        else:
            self._send({"label": text})

    def _on_options_editing_finished(self) -> None:
        skill = self.skill
        if skill is None:
            return
        timeout, retries = self.timeout_spin.value(), self.retries_spin.value()
        if not self.editable:
            if timeout != skill.timeout or retries != skill.max_retries:
                self._not_planned(skill, "time limit and retries")
                self._show_options(skill, force=True)
            return
        for spin in (self.timeout_spin, self.retries_spin):
            spin.setStyleSheet("")
        try:
            checked = {"timeout": check_timeout(timeout)}
        except InvalidRequest as error:
            self.timeout_spin.setStyleSheet(INVALID_STYLE)
            self.problem.emit(f"Not sent: {error} (0 s: no time limit).")
            return
        try:
            checked["max_retries"] = check_retries(int(retries))
        except InvalidRequest as error:
            self.retries_spin.setStyleSheet(INVALID_STYLE)
            self.problem.emit(f"Not sent: {error}.")
            return
        if timeout != skill.timeout or retries != skill.max_retries:
            self._send(checked)

    def reverter(self, skill_id: str) -> Callable[[Answer], None]:
        """A callback for the answer to an edit of ``skill_id``: refused, show the server's
        values again (even in the field that has the focus, so it is not sent again)."""

        def revert(answer: Answer) -> None:
            newest = self._view.skill(skill_id)
            if answer.ok or newest is None or self.skill is None or self.skill.id != skill_id:
                return
            self.skill = newest
            self.label_edit.setText(newest.label)
            self.timeout_spin.setValue(newest.timeout)
            self.retries_spin.setValue(newest.max_retries)
            for widget in (self.label_edit, self.timeout_spin, self.retries_spin):
                widget.setStyleSheet("")
            for name, editor in self.editors.items():
                if name in newest.params:
                    editor.blockSignals(True)
                    editor.set_value(newest.params[name])
                    editor.mark_invalid(False)
                    editor.blockSignals(False)

        return revert

    def _not_planned(self, skill: SkillInstance, what: str) -> None:
        """Say that an edit typed while the skill left the plan was not sent (never lose it
        without a word: the skill may have been sent to the robot meanwhile)."""
        if self._read_only:
            return
        self.problem.emit(
            f"Not sent: '{skill.label or skill.skill}' on {skill.agent} is no longer planned "
            f"(it is {self._view.status_text(skill)}), so its {what} stays as it was; "
            "take it back from the robot to change it."
        )

    def _send(self, fields: dict[str, Any]) -> None:
        assert self.skill is not None
        self.edit_requested.emit(self.skill.id, fields)


def _typed(editor: Editor) -> object:
    """What ``editor`` holds, as the mission keeps it (None when it cannot be read)."""
    try:
        return editor.value()
    except (InvalidRequest, ValueError):
        return None


def _data(value: object) -> object:
    to_dict = getattr(value, "to_dict", None)
    return to_dict() if callable(to_dict) else value
