"""Simulation in pure Python (pybullet allowed here): world, robots, skills, link model."""
