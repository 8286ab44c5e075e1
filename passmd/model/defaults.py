"""The protocol defaults: one record that the command line, the chapters and the tests share.

The paper fixes some protocol values (Section 4.1's 100 Hz saw-tooth, Section 2's two and
four contacts per side); others are ours (the discrete contact's number of springs, the
step threshold of the critical-amplitude search). Each is defined here once; modules import
:data:`PROTOCOL` instead of retyping a number.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["PROTOCOL", "ProtocolDefaults"]


#: Driving frequency f of the saw-tooth in Sections 4.1, 4.2 and 5.1 [Hz].
_DRIVE_FREQUENCY = 100.0


class ProtocolDefaults(NamedTuple):
    """Defaults of the simulation protocols (SI units)."""

    #: Driving frequency f of the saw-tooth in Sections 4.1, 4.2 and 5.1 [Hz].
    drive_frequency: float = _DRIVE_FREQUENCY
    #: Springs N of the discrete MDR contact (converged in the MDR-validation chapter).
    springs: int = 200
    #: Contacts on the two sides of the runner in the six-contact drive (Section 2).
    contacts_per_side: tuple[int, int] = (2, 4)
    #: Step threshold S of the steady-state critical-amplitude search: a step counts when the
    #: last step of a run exceeds it (ours; Section 4.1 does not define "a step") [m].
    step_threshold: float = 0.5e-9
    #: Saw-tooth periods of one steady-state run of that search; its last step counts.
    steady_periods: int = 10
    #: The search stops when its bisection bracket is narrower than this [m].
    search_tolerance: float = 0.1e-9
    #: Periods after which the force protocol (Section 4.2) first checks for stall; the run is
    #: then lengthened until it stalls.
    stall_periods: int = 64
    #: Longest stall run before a point is reported as not stalled (periods).
    stall_max_periods: int = 4096
    #: Drive frequencies over which the spread of the steady-state critical amplitude is
    #: drawn as a band (Section 4.1; the band brackets ``drive_frequency``) [Hz].
    critical_amplitude_band: tuple[float, ...] = (0.5 * _DRIVE_FREQUENCY, _DRIVE_FREQUENCY,
                                                  2.0 * _DRIVE_FREQUENCY)


#: The defaults every protocol uses unless the caller says otherwise.
PROTOCOL = ProtocolDefaults()
