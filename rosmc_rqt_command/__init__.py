"""ROSMC command GUI: Qt models and widgets, mission client, rqt plugin and standalone window."""
