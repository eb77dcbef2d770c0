"""The skill library: agents, their skills and typed parameters, lost-link policies, ``extends``.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
