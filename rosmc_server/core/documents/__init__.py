"""Reading YAML documents with precise errors, and writing files that survive a crash.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
