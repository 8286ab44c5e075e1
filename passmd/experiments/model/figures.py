"""The model chapter's figures (Sections 2–3): the driving signal, the macroscopic model's
normal forces (Eq. 1) and one MDR contact's force loop (Eqs. 4–6).

Each compute function takes a :class:`~passmd.runtime.config.RunConfig` (the figures are cheap and
the same on every profile) and returns a tidy DataFrame with SI columns and the display
columns the plots of :mod:`passmd.plots.model` read. The drive is the paper's R = 1 mm drive
at F_p = 0.4 N (:func:`model_drive`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec
from passmd.experiments.critical_amplitude_one.figures import FIG5A_DRIVE
from passmd.model import hertz, theory
from passmd.model.defaults import PROTOCOL
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive, paper_drive
from passmd.model.waveforms import flyback_time, sawtooth
from passmd.runtime.config import RunConfig
from passmd.runtime.units import from_si

__all__ = [
    "FIGURES",
    "MODEL_PRELOAD",
    "MODEL_RADIUS",
    "MDR_LOOP_SPRINGS",
    "SAWTOOTH_PERIODS",
    "model_cross_section",
    "model_drive",
    "model_free_body",
    "model_mdr_loop",
    "model_sawtooth",
    "normal_force_balance",
]

#: Hemisphere radius R (m) and preload F_p (N) of the model chapter's drive (Table 2, Fig. 5a).
MODEL_RADIUS, MODEL_PRELOAD = FIG5A_DRIVE
#: Periods of the saw-tooth drawn for Figs. 1d and 3c.
SAWTOOTH_PERIODS = 3
#: Discrete springs of the force loop drawn against the exact contact (Fig. 4b).
MDR_LOOP_SPRINGS = 50


def model_drive(hemisphere_radius: float = MODEL_RADIUS) -> Drive:
    """The paper's drive of radius ``hemisphere_radius`` at the model chapter's preload."""
    return paper_drive(hemisphere_radius, MODEL_PRELOAD)


def model_sawtooth(config: RunConfig) -> pd.DataFrame:
    """Saw-tooth piezo position x_p(t) of Figs. 1d and 3c at full stroke and the drive frequency.

    Returns
    -------
    DataFrame
        One row per waveform corner: ``time_s, x_p_m, time_ms, x_p_nm``, and the scalars
        ``amplitude_m``, ``frequency_Hz``, ``periods``, ``ramp_end_s`` (end of the first
        ramp), ``flyback_time_s`` (:func:`passmd.model.waveforms.flyback_time`).
    """
    drive = model_drive()
    amplitude = drive.actuator.full_stroke_amplitude
    wave = sawtooth(amplitude, PROTOCOL.drive_frequency, drive, periods=SAWTOOTH_PERIODS)
    t = np.asarray(wave.times)
    x = np.asarray(wave.positions)
    return pd.DataFrame(
        {
            "time_s": t,
            "x_p_m": x,
            "time_ms": from_si(t, "ms"),
            "x_p_nm": from_si(x, "nm"),
            "amplitude_m": amplitude,
            "frequency_Hz": PROTOCOL.drive_frequency,
            "periods": wave.periods,
            "ramp_end_s": float(wave.slip_marks[0]),
            "flyback_time_s": flyback_time(amplitude, drive),
        }
    )


def normal_force_balance(drive: Drive) -> dict:
    """Normal forces of Eq. 1 and the preload their horizontal components carry on each side.

    Returns
    -------
    dict
        ``preload_N``, ``normal_force_1_N`` (F_N1), ``normal_force_2_N`` (F_N2),
        ``balance_right_N`` (2 F_N1 sin 45°) and ``balance_left_N`` (4 F_N2 sin 45°), both
        equal to F_p.
    """
    f1, f2 = (float(f) for f in drive.contact_layout.normal_forces)
    return {
        "preload_N": drive.preload,
        "normal_force_1_N": f1,
        "normal_force_2_N": f2,
        "balance_right_N": 2 * f1 * np.sin(np.pi / 4),
        "balance_left_N": 4 * f2 * np.sin(np.pi / 4),
    }


def model_free_body(config: RunConfig) -> pd.DataFrame:
    """Data of the free-body diagram of the macroscopic model (Fig. 3a): Eq. 1's normal forces."""
    return pd.DataFrame([normal_force_balance(model_drive())])


def model_cross_section(config: RunConfig) -> pd.DataFrame:
    """Data of the runner's cross-section (Fig. 3b): Eq. 1's normal forces and their balance."""
    return pd.DataFrame([normal_force_balance(model_drive())])


def model_mdr_loop(config: RunConfig) -> pd.DataFrame:
    """One side-1 contact (Fig. 4): Hertz geometry and its friction force along a loading loop.

    The path loads from rest to 0.8 u_x,max (Eq. 7), unloads to −0.8 u_x,max and reloads,
    with the exact contact and with :data:`MDR_LOOP_SPRINGS` discrete springs (Eqs. 4–6).

    Returns
    -------
    DataFrame
        One row per path point: ``u_m, force_exact_N, force_discrete_N`` and the display
        columns ``u_nm, force_exact_mN, force_<N>_springs_mN``; scalars ``normal_force_N``,
        ``hemisphere_radius_m``, ``contact_radius_m`` (a), ``indentation_m`` (d),
        ``presliding_m`` (u_x,max), ``sliding_force_N`` (μF_N), ``springs``.
    """
    drive = model_drive()
    f1 = float(drive.contact_layout.normal_forces[0])
    e_star, g_star = drive.contact_moduli
    radius = drive.hemisphere_radius
    mu = drive.friction_coefficient
    u_max = float(theory.presliding_displacement(f1, radius, e_star, g_star, mu))
    amp = 0.8 * u_max
    path = np.concatenate(
        [np.linspace(0, amp, 120), np.linspace(amp, -amp, 240), np.linspace(-amp, amp, 240)]
    )
    exact = MDRContact.for_drive(drive, side=0).path(path)
    discrete = MDRContact.for_drive(drive, side=0, springs=MDR_LOOP_SPRINGS).path(path)
    return pd.DataFrame(
        {
            "u_m": path,
            "force_exact_N": exact,
            "force_discrete_N": discrete,
            "u_nm": from_si(path, "nm"),
            "force_exact_mN": from_si(exact, "mN"),
            f"force_{MDR_LOOP_SPRINGS}_springs_mN": from_si(discrete, "mN"),
            "normal_force_N": f1,
            "hemisphere_radius_m": radius,
            "contact_radius_m": float(hertz.hertz_contact_radius(f1, radius, e_star)),
            "indentation_m": float(hertz.hertz_indentation(f1, radius, e_star)),
            "presliding_m": u_max,
            "sliding_force_N": mu * f1,
            "springs": MDR_LOOP_SPRINGS,
        }
    )


#: The chapter's rows of the figure table.
FIGURES = (
    FigureSpec("model_sawtooth", "Saw-tooth piezo position x_p(t) at full stroke (Figs. 1d, 3c)",
               "model", model_sawtooth, "model:plot_sawtooth"),
    FigureSpec("model_free_body", "Free-body diagram of the macroscopic model, Eqs. 2-3 (Fig. 3a, schematic)",
               "model", model_free_body, "model:plot_free_body"),
    FigureSpec("model_cross_section", "Cross-section of the runner with the normal forces of Eq. 1 (Fig. 3b)",
               "model", model_cross_section, "model:plot_cross_section"),
    FigureSpec("model_mdr_loop", "The 1-D MDR contact and its force loop, exact and 50 springs (Fig. 4)",
               "model", model_mdr_loop, "model:plot_mdr_loop"),
)
