"""ROSMC mission server: mission model, robot link, MCAP journal and replay, CLI."""
