"""Tables the model chapter shows (Sections 2–4): the closed forms of a six-contact drive and Table 2's
actuators, formatted in display units."""

from __future__ import annotations

from passmd.model import theory
from passmd.model.parameters import Drive
from passmd.runtime.units import from_si

__all__ = ["actuator_row", "closed_form_rows"]


def closed_form_rows(drive: Drive) -> dict[str, str]:
    """The closed forms of Section 4 for a six-contact drive, formatted for the model chapter.

    Values of :func:`passmd.model.theory.drive_theory` (Eqs. 1, 4, 7, 9–14) and the runner's
    frequency on its contacts, in display units, 4 significant digits (2aG*: 3), two sides
    joined by ", ".
    """
    th = theory.drive_theory(drive)

    def join(values, unit, digits=4):
        return ", ".join(f"{from_si(v, unit):.{digits}g}" for v in values)

    return {
        "E* (GPa)": f"{from_si(th['E_star_Pa'], 'GPa'):.4g}",
        "G* (GPa)": f"{from_si(th['G_star_Pa'], 'GPa'):.4g}",
        "F_N1, F_N2 (N)": join(th["normal_force_N"], "N"),
        "a₁, a₂ (µm)": join(th["contact_radius_m"], "um"),
        "2aG* per contact (N/m)": join(th["tangential_stiffness_N_per_m"], "N/m", 3),
        "u_x,max,1, u_x,max,2 (nm), Eq. 10": join(th["presliding_m"], "nm"),
        "u_x,a,1, u_x,a,2 (nm), Eq. 14": join(th["actuator_deformation_m"], "nm"),
        "u_x,max,e rigid (nm), Eq. 11": f"{from_si(th['critical_amplitude_rigid_m'], 'nm'):.4g}",
        "u*_x,max,e flexible (nm), Eq. 12": f"{from_si(th['critical_amplitude_flexible_m'], 'nm'):.4g}",
        "runner on its contacts (kHz)": f"{from_si(theory.runner_frequency(drive), 'kHz'):.4g}",
    }


def actuator_row(drive: Drive) -> dict[str, str]:
    """Table 2's actuator of a drive and its bare natural frequency √(k_p/m_a)/2π, formatted."""
    actuator = drive.actuator
    return {
        "drive": f"R = {from_si(drive.hemisphere_radius, 'mm'):.3g} mm",
        "k_p (N/m)": f"{actuator.stiffness:.3g}",
        "m_a (g)": f"{from_si(actuator.mass, 'g'):.3g}",
        "bare actuator √(k_p/m_a)/2π (MHz)": f"{actuator.natural_frequency / 1e6:.3g}",
        "damping ratio ζ (assumed)": f"{actuator.damping_ratio:.3g}",
    }
