"""The task panel: one :class:`AgentColumn` per robot, side by side, scrolling sideways.

Owns the selection across columns: a plain click selects in one table only; Ctrl or
Shift keep what other columns have selected (a barrier spans robots). The selection is
a list of skill ids that survives live updates: after rows change, the same skills are
selected again wherever they are now (a skill moves from the blueprint to the
synchronized table when it is uploaded).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from python_qt_binding.QtCore import (
    QItemSelection,
    QItemSelectionModel,
    QPoint,
    Qt,
    QTimer,
    Signal,
)
from python_qt_binding.QtWidgets import QApplication, QHBoxLayout, QScrollArea, QWidget

from rosmc_server.core import AgentStatus, Library

from ..core.mission_view import MissionView
from ..core.view_state import ViewUpdate, delta_agent
from .agent_column import COMPACT_WIDTH, AgentColumn
from .section_table import SectionTable

# A mission's first columns are built at once, as many as fit on screen (at least this
# many); the others follow in groups of LATER_COLUMNS, LATER_MS apart (a zero timer could
# run before the window has painted the first ones).
FIRST_COLUMNS = 6
LATER_COLUMNS = 4
LATER_MS = 10


class TaskWidget(QScrollArea):  # type: ignore[misc]
    """Every robot's task; emits the selection and the operator's requests."""

    selection_changed = Signal(list)  # selected skill ids
    context_menu_requested = Signal(object, QPoint)  # table, global position
    robot_action = Signal(str, object)  # agent, RobotAction
    add_requested = Signal(str, str)  # agent, skill
    policy_chosen = Signal(str, object)  # agent, LostLinkPolicy
    reorder_requested = Signal(str, list)  # agent, new blueprint order
    columns_added = Signal(list)  # robots whose columns came after the first paint

    def __init__(self, view: MissionView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._view = view
        self.columns: dict[str, AgentColumn] = {}
        self._selected: list[str] = []
        self._syncing = False
        self._library: Library | None = None
        self._later: list[str] = []  # robots whose columns are yet to be added
        self._inner = QWidget()
        self._row = QHBoxLayout(self._inner)
        self._row.setContentsMargins(2, 2, 2, 2)
        self._row.addStretch(0)  # columns take the width first, up to their maximum
        self.setWidget(self._inner)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarAsNeeded)

    # -- content --------------------------------------------------------------------------
    @property
    def complete(self) -> bool:
        """Every robot of the mission has its column (none is waiting to be added)."""
        return not self._later

    @property
    def selected_ids(self) -> list[str]:
        """The selected skills, robot by robot, top to bottom."""
        return list(self._selected)

    def set_library(self, library: Library) -> None:
        """Offer each robot's skills in its Add menu."""
        self._library = library
        for agent, column in self.columns.items():
            self._offer_skills(agent, column)

    def apply(self, update: ViewUpdate) -> None:
        """Show what ``update`` changed (the view has taken it already)."""
        self._syncing = True  # rows come and go: the selection is restored afterwards
        try:
            self._apply(update)
        finally:
            self._syncing = False

    def _apply(self, update: ViewUpdate) -> None:
        if update.reset:
            self._ensure_columns([view.agent for view in update.agents])
        touched: list[AgentColumn] = []
        for agent in update.touched:
            column = self.columns.get(agent)
            if column is None:
                continue
            task = self._view.view(agent)
            if update.reset:
                column.show_task(task)
            else:
                column.apply(task, [d for d in update.deltas if delta_agent(d) == agent])
            touched.append(column)
        if update.barriers is not None or update.reset:
            touched = list(self.columns.values())
            for column in touched:
                column.synced_model.refresh()
                column.blueprint_model.refresh()
        elif update.changed_ids and self._view.barriers:
            self._refresh_partners(update.changed_ids)
        self._restore(touched)

    def _refresh_partners(self, changed: Iterable[str]) -> None:
        """Repaint barrier partners of changed skills ("waiting on <robot>" may change)."""
        for skill_id in changed:
            barrier = self._view.barrier_of(skill_id)
            if barrier is None:
                continue
            for partner in self._view.skills(barrier.skill_ids):
                column = self.columns.get(partner.agent)
                if partner.id != skill_id and column is not None:
                    for model in (column.synced_model, column.blueprint_model):
                        model.refresh_skill(partner.id)

    def show_statuses(self, statuses: Iterable[AgentStatus]) -> None:
        """Show the robots' latest reports in their column headers."""
        for status in statuses:
            column = self.columns.get(status.agent)
            if column is not None:
                column.show_status(status)

    def select_ids(self, skill_ids: Sequence[str]) -> None:
        """Select these skills (e.g. chosen in rviz) and scroll to the first."""
        self._selected = [i for i in skill_ids if self._view.skill(i) is not None]
        self._restore(list(self.columns.values()))
        for table in self.tables():
            row = table.section.row_of(self._selected[0]) if self._selected else -1
            if row >= 0:
                self._reveal(table.parentWidget())
                table.scrollTo(table.section.index(row, 0))
                break
        self.selection_changed.emit(self.selected_ids)

    def _reveal(self, column: QWidget) -> None:
        """Scroll sideways to ``column`` only if none of it is in view: a column the
        operator just clicked in must stay under the pointer (after *Add skill*, a sideways
        jump put another robot's button where the next click went)."""
        left = column.mapTo(self._inner, QPoint(0, 0)).x() - self.horizontalScrollBar().value()
        if left >= self.viewport().width() or left + column.width() <= 0:
            self.ensureWidgetVisible(column)

    def clear_selection(self) -> None:
        """Select nothing."""
        self.select_ids([])

    def tables(self) -> Iterable[SectionTable]:
        """Every table, robot by robot, synchronized first."""
        for column in self.columns.values():
            yield from column.tables

    def table_of(self, skill_id: str) -> SectionTable | None:
        """The table that shows ``skill_id``."""
        for table in self.tables():
            if table.section.row_of(skill_id) >= 0:
                return table
        return None

    # -- columns --------------------------------------------------------------------------
    def _ensure_columns(self, agents: list[str]) -> None:
        """One column per robot, in order: those that fit on screen now, the rest after
        the window has painted them (a column costs milliseconds to build and show)."""
        if list(self.columns) + self._later == agents:
            return
        for column in self.columns.values():
            self._row.removeWidget(column)
            column.deleteLater()
        self.columns = {}
        first = max(FIRST_COLUMNS, self.viewport().width() // COMPACT_WIDTH + 1)
        for agent in agents[:first]:
            self._add_column(agent)
        self._later = agents[first:]
        if self._later:
            QTimer.singleShot(LATER_MS, self._on_later_timeout)

    def _on_later_timeout(self) -> None:
        """Add the next few columns that did not fit on screen, showing their tasks."""
        if not self._later:  # a newer mission's columns were all built meanwhile
            return
        added = [self._add_column(agent) for agent in self._later[:LATER_COLUMNS]]
        del self._later[:LATER_COLUMNS]
        for column in added:
            column.show_task(self._view.view(column.agent))
        self._restore(added)
        if self._later:
            QTimer.singleShot(LATER_MS, self._on_later_timeout)
        self.columns_added.emit([column.agent for column in added])

    def _add_column(self, agent: str) -> AgentColumn:
        column = AgentColumn(agent, self._view, self._inner)
        self._row.insertWidget(len(self.columns), column, 1)
        self.columns[agent] = column
        column.robot_action.connect(self.robot_action)
        column.add_requested.connect(self.add_requested)
        column.policy_chosen.connect(self.policy_chosen)
        column.blueprint_model.reorder_requested.connect(self.reorder_requested)
        column.show_status(self._view.statuses.get(agent))
        self._offer_skills(agent, column)
        for table in column.tables:
            table.selectionModel().selectionChanged.connect(
                lambda *_args, t=table: self._on_table_selection_changed(t)
            )
            table.empty_clicked.connect(self.clear_selection)
            table.plain_clicked.connect(lambda t=table: self._on_table_plain_clicked(t))
            table.customContextMenuRequested.connect(
                lambda pos, t=table: self._on_table_context_menu(t, pos)
            )
        return column

    def _offer_skills(self, agent: str, column: AgentColumn) -> None:
        if self._library is not None and agent in self._library.dynamic_agents:
            column.set_skills(list(self._library.skills_of(agent)))
            column.default_policy = self._library.default_policy(agent)

    # -- selection ------------------------------------------------------------------------
    def _on_table_plain_clicked(self, table: SectionTable) -> None:
        """A plain click selects in one table only: the others let go first."""
        if any(o.selectionModel().hasSelection() for o in self.tables() if o is not table):
            self._clear_others(table)
            self._collect()

    def _clear_others(self, table: SectionTable) -> None:
        self._syncing = True
        try:
            for other in self.tables():
                if other is not table:
                    other.clearSelection()
        finally:
            self._syncing = False

    def _on_table_selection_changed(self, table: SectionTable) -> None:
        if self._syncing:
            return
        modifiers = QApplication.keyboardModifiers() | table.last_modifiers
        keep_others = bool(modifiers & (Qt.ControlModifier | Qt.ShiftModifier))
        if not keep_others and table.selectionModel().hasSelection():
            self._clear_others(table)
        self._collect()

    def _collect(self) -> None:
        self._selected = [
            skill.id
            for other in self.tables()
            for row in sorted(i.row() for i in other.selectionModel().selectedRows())
            if (skill := other.section.skill_at(row)) is not None
        ]
        self.selection_changed.emit(self.selected_ids)

    def _on_table_context_menu(self, table: SectionTable, pos: QPoint) -> None:
        index = table.indexAt(pos)
        if index.isValid() and not table.selectionModel().isRowSelected(
            index.row(), index.parent()
        ):
            table.selectRow(index.row())
        self.context_menu_requested.emit(table, table.viewport().mapToGlobal(pos))

    def _restore(self, tables_of: Iterable[AgentColumn]) -> None:
        """Select the remembered skills again in the given columns' tables."""
        wanted = set(self._selected)
        syncing, self._syncing = self._syncing, True
        try:
            for column in tables_of:
                for table in column.tables:
                    model = table.section
                    selection = QItemSelection()
                    for row, skill in enumerate(model.rows):
                        if skill.id in wanted:
                            selection.select(model.index(row, 0), model.index(row, 4))
                    current = {i.row() for i in table.selectionModel().selectedRows()}
                    rows = {r for r, s in enumerate(model.rows) if s.id in wanted}
                    if current != rows:
                        table.selectionModel().select(
                            selection, QItemSelectionModel.ClearAndSelect | QItemSelectionModel.Rows
                        )
        finally:
            self._syncing = syncing
