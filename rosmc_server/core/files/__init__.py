"""Mission files: versioned YAML read fast and precisely, and written fast.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
