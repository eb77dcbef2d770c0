"""The generic on-robot mission executor: runs synchronized skills without the ground station."""
