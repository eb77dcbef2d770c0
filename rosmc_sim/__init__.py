"""ROSMC simulation: pybullet world, robot kinds, simulated skills and comm-link model."""
