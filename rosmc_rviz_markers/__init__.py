"""ROSMC interactive-marker servers for rviz: agents, static agents, task markers, icons."""
