"""The questions before a send: a team send, or a barrier member whose partners stay behind."""

from __future__ import annotations

from python_qt_binding.QtWidgets import QMessageBox, QWidget


def ask_team_send(parent: QWidget, text: str, warnings: list[str]) -> bool:
    """Ask once whether to send a whole task (or several); the default never sends.

    Enter, Escape or closing the question sends nothing: only a click on *Send* does.
    """
    box = QMessageBox(parent)
    box.setObjectName("team_send_question")
    box.setIcon(QMessageBox.Warning if warnings else QMessageBox.Question)
    box.setWindowTitle("Send to the robots?")
    if warnings:
        text += "\n\nWarnings:\n" + "\n".join(f"  • {w}" for w in warnings)
    box.setText(text + "\n\nSend?")
    box.setStandardButtons(QMessageBox.Yes | QMessageBox.No)
    box.button(QMessageBox.Yes).setText("Send")
    box.button(QMessageBox.No).setText("Don't send")
    box.setDefaultButton(QMessageBox.No)
    box.setEscapeButton(QMessageBox.No)
    return bool(box.exec_() == QMessageBox.Yes)


def ask_send_anyway(parent: QWidget, warnings: list[str]) -> bool:
    """Ask whether to send although a robot would wait for ever (No is the default)."""
    answer = QMessageBox.warning(
        parent,
        "A robot would wait for ever",
        "\n".join(warnings) + "\n\nSend anyway?",
        QMessageBox.Yes | QMessageBox.No,
        QMessageBox.No,
    )
    return bool(answer == QMessageBox.Yes)
