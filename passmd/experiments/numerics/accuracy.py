"""Accuracies the default integrator guarantees for what the figures report.

Each is checked by running the quick figure data again with the step halved (error-controlled
tolerance ÷ 16): every reported value moves by well under its stated accuracy, so any integrator
at least as accurate reproduces the figures within them. The regression snapshots compare with
them (``tests/snapshot_accuracy.py``), and the chapters quote them.
"""

from __future__ import annotations

from passmd.protocols import stall
from passmd.solver import steps

#: Positions, steps and back-steps (m): :data:`passmd.solver.steps.CONVERGED_ACCURACY`, the
#: settled position's distance from a much finer run. Halving the step moved no quick step,
#: back-step or settled position (Figs. 5a, 7–10) by more than 0.012 nm.
POSITION_ACCURACY = steps.CONVERGED_ACCURACY
#: Stall forces (N): the stall criterion's absolute tolerance
#: (:data:`passmd.protocols.stall.STALL_ABS_TOLERANCE`) — a finer run may stop a few periods
#: earlier or later, anywhere within it — plus :data:`STALL_FORCE_RTOL` of the force. The
#: integrator's own share, k_l·POSITION_ACCURACY ≈ 1 µN, is far below; halving the step moved
#: no quick force of Fig. 7 by more than 0.018 mN.
FORCE_ACCURACY = stall.STALL_ABS_TOLERANCE
#: Relative part of the stall-force accuracy (:data:`passmd.protocols.stall.STALL_REL_TOLERANCE`).
STALL_FORCE_RTOL = stall.STALL_REL_TOLERANCE
#: Steady velocities (m/s): a step per period accurate to POSITION_ACCURACY at the fastest
#: step frequency of Figs. 9b–10 (130 kHz), 6.5 µm/s. Halving the step moved none by more
#: than 1.4 µm/s.
VELOCITY_ACCURACY = POSITION_ACCURACY * 130e3
#: Micro-vibration frequencies and times (Eq. 15's t_s, t_a; turning points; the stall cycle's
#: full-slip time), relative: read off the recorded samples, so quantised to the record
#: spacing, which follows the step. Halving the step moved f_s and Eq. 15's times by at most
#: 3.2e-6 and the full-slip time by one record spacing, 1.5e-4; 1e-3 leaves a factor 6.
FREQUENCY_RTOL = 1e-3
#: Slip shares (fraction of a contact's radius sliding): they change fastest at the turning
#: points where Fig. 8 reads them, by up to 0.006 when the step was halved (their means and
#: maxima over a phase by 0.0004); 0.02 leaves a factor 3.
SLIP_SHARE_ACCURACY = 0.02
#: Critical amplitudes and force onsets, in final bracket widths of their search (its
#: ``tolerance``) plus POSITION_ACCURACY: the integrator's error can flip a bisection decision
#: only at an amplitude within that error of the switch, which moves the reported midpoint by
#: one width. Halving the step changed no quick critical amplitude or onset (Figs. 5–7).
CRITICAL_AMPLITUDE_BRACKETS = 1.0
