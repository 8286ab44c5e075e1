"""Protocols: the paper's measurement procedures as pure functions of a drive.

Each takes a :class:`~passmd.model.parameters.Drive` (and the protocol defaults of
:mod:`passmd.model.defaults`) and runs the simulator of :mod:`passmd.solver.simulation`: the
critical-amplitude search (Section 4.1), the stall criterion of the force measurement
(Section 4.2) and the Eq. 15 design of the optimized waveform from a measured response
(Section 5.1). They know nothing of figures, grids or the ledger.
"""
