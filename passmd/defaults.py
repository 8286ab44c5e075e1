"""The protocol defaults: one record that the command line, the chapters and the tests share.

The paper fixes some protocol values (Section 4.1's 100 Hz saw-tooth, Section 2's two and
four contacts per side); others are ours (the discrete contact's number of springs, the
step threshold of the critical-amplitude search). Each is defined here once; modules import
:data:`PROTOCOL` instead of retyping a number.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["PROTOCOL", "ProtocolDefaults"]


class ProtocolDefaults(NamedTuple):
    """Defaults of the simulation protocols (SI units)."""

    #: Driving frequency f of the saw-tooth in Sections 4.1, 4.2 and 5.1 [Hz].
    drive_frequency: float = 100.0
    #: Springs N of the discrete MDR contact (converged in the MDR-validation chapter).
    springs: int = 200
    #: Contacts on the two sides of the runner in the six-contact drive (Section 2).
    contacts_per_side: tuple[int, int] = (2, 4)
    #: Drive frequencies over which the spread of the steady-state critical amplitude is
    #: drawn as a band (Section 4.1; the band brackets ``drive_frequency``) [Hz].
    critical_amplitude_band: tuple[float, ...] = (50.0, 100.0, 200.0)


#: The defaults every protocol uses unless the caller says otherwise.
PROTOCOL = ProtocolDefaults()
