"""What every view of a mission shares: words, marks and colours, drawing primitives,
the science score.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
