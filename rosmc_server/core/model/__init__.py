"""The mission model: skills, barriers, markers, tasks in order, the state,
and changes between revisions.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
