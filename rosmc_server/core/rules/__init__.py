"""The operator rules: the mission object and every operation it accepts or refuses.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
