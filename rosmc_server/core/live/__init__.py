"""Events applied to a mission state, and a client's live copy of the mission.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
