"""The paper's closed-form reference curves (Figs. 5b, 6a–c) and the reference data folder.

Figs. 5b and 6a–c draw, next to the simulated critical amplitude A_c, the closed forms
of Section 4.1 on the preload grid:

* Fig. 5b (one contact, R = 1 mm): u_x,max (Eq. 7) and u_x,max + u_x,a (Eq. 8, 9);
* Fig. 6a (six contacts, R = 1 mm, rigid): u_x,max,1, u_x,max,2 (Eq. 10), u_x,max,e (Eq. 11);
* Fig. 6b/6c (six contacts, flexible, R = 1 mm / 0.25 mm): u*_x,max,1, u*_x,max,2
  (Eqs. 13, 14) and u*_x,max,e (Eq. 12).

:func:`closed_form_curves` computes them with :mod:`passmd.model.theory`;
``tools/make_reference_curves.py`` writes them into the repository's reference data folder,
``passmd/data/reference/`` (installed with the package as package data), with
:func:`write_reference_curves`, and :func:`load_reference_curve` reads them back.
Lengths are in nm, forces in N (the units of the CSV files and of the figures).
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from passmd.model import hertz, theory
from passmd.model.parameters import paper_drive
from passmd.model.tables import PRELOAD_GRIDS, Assumption
from passmd.runtime.inputs import decode_text, read_bounded
from passmd.runtime.outputs import write_files
from passmd.runtime.validation import check_choice

__all__ = [
    "CURVES",
    "REFERENCE_DIR",
    "REFERENCE_FRICTION_COEFFICIENT",
    "CurveSpec",
    "closed_form_curves",
    "curve_header",
    "load_reference_curve",
    "tangential_stiffness_table",
    "write_reference_curves",
]

#: The reference data folder, ``passmd/data/reference/``: package data, read-only (found with
#: :mod:`importlib.resources`, so it is the installed copy for an installed package).
REFERENCE_DIR = Path(os.fspath(resources.files("passmd") / "data" / "reference"))

#: μ of the Section 4.1 reference curves: the paper does not state it there.
REFERENCE_FRICTION_COEFFICIENT = 0.2

ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        key="friction_coefficient_sections_4_1_and_5",
        symbol="μ",
        value=f"{REFERENCE_FRICTION_COEFFICIENT:g}",
        unit="–",
        rationale=(
            "Sections 4.1 (Figs. 5, 6) and 5 (Figs. 8–10) do not state μ; Table 1 lists 0.2 and 0.3. "
            "Section 4.2 uses 0.2, measured by Lübke [24], as the realistic value, and 0.3 only for "
            "the earlier work's rigid model. The closed-form reference curves use 0.2. Each section "
            "chooses its own μ: the ledger evaluates 0.2 and 0.3 for Section 4.1 and for Section 5 "
            "apart (passmd.ledger.readings)."
        ),
        sensitivity=(
            "Every closed form of Eqs. 7–14 is proportional to μ, so μ = 0.3 would raise all "
            "reference curves of Figs. 5b and 6a–c by 50 %; the replication report shows every claim "
            "at both values of its section."
        ),
    ),
)

_NM = 1e9  # m → nm


@dataclass(frozen=True)
class CurveSpec:
    """One reference-curve table: the figure, its configuration and its columns."""

    name: str  # file stem, e.g. "fig5b_closed_form"
    figure: str  # the paper's panel, e.g. "5b"
    hemisphere_radius: float  # R in m
    contacts: int  # 1 or 6
    columns: dict[str, str]  # column name -> what it is (equation)

    @property
    def filename(self) -> str:
        return f"{self.name}.csv"


#: Every reference-curve table by file stem (Figs. 5b, 6a, 6b, 6c).
CURVES: dict[str, CurveSpec] = {
    spec.name: spec
    for spec in (
        CurveSpec(
            "fig5b_closed_form", "5b", 1.0e-3, 1,
            {
                "preload_N": "preload F_p (one contact: F_N = F_p)",
                "u_x_max_nm": "u_x,max, presliding displacement (Eq. 7); A_c of a rigid actuator",
                "u_x_a_nm": "u_x,a, actuator deformation (Eq. 9)",
                "u_x_max_plus_u_x_a_nm": "u_x,max + u_x,a (Eq. 8); A_c of a flexible actuator",
            },
        ),
        CurveSpec(
            "fig6a_closed_form", "6a", 1.0e-3, 6,
            {
                "preload_N": "preload F_p",
                "u_x_max_1_nm": "u_x,max,1, presliding of a right-hand contact, F_N1 (Eqs. 1, 10)",
                "u_x_max_2_nm": "u_x,max,2, presliding of a left-hand contact, F_N2 (Eqs. 1, 10)",
                "u_x_max_e_nm": "u_x,max,e = 2 u1 u2/(u1 + u2) (Eq. 11); A_c of rigid actuators",
            },
        ),
        *(
            CurveSpec(
                name, figure, radius, 6,
                {
                    "preload_N": "preload F_p",
                    "u_x_a_1_nm": "u_x,a,1, actuator deformation at F_N1 (Eq. 14)",
                    "u_x_a_2_nm": "u_x,a,2, actuator deformation at F_N2 (Eq. 14)",
                    "u_x_max_1_star_nm": "u*_x,max,1 = u_x,max,1 + u_x,a,1 (Eq. 13)",
                    "u_x_max_2_star_nm": "u*_x,max,2 = u_x,max,2 + u_x,a,2 (Eq. 13)",
                    "u_x_max_e_star_nm": "u*_x,max,e = 2 u*1 u*2/(u*1 + u*2) (Eq. 12); A_c of flexible "
                                         "actuators",
                },
            )
            for name, figure, radius in (
                ("fig6b_closed_form", "6b", 1.0e-3),
                ("fig6c_closed_form", "6c", 0.25e-3),
            )
        ),
    )
}


def _spec(name: str) -> CurveSpec:
    stem = name[:-4] if isinstance(name, str) and name.endswith(".csv") else name
    return CURVES[check_choice("name", stem, tuple(CURVES))]


def closed_form_curves(
    name: str, friction_coefficient: float = REFERENCE_FRICTION_COEFFICIENT
) -> pd.DataFrame:
    """Compute one reference-curve table on the paper's preload grid.

    Parameters
    ----------
    name : str
        One of :data:`CURVES` (``"fig5b_closed_form"``, ``"fig6a_closed_form"``,
        ``"fig6b_closed_form"``, ``"fig6c_closed_form"``); a trailing ``.csv`` is accepted.
    friction_coefficient : float
        μ of Eqs. 7, 9, 10 and 14 (default :data:`REFERENCE_FRICTION_COEFFICIENT`).

    Returns
    -------
    pandas.DataFrame
        ``preload_N`` on :data:`passmd.model.tables.PRELOAD_GRIDS` for the figure's radius,
        then the columns of ``CURVES[name].columns`` in nm.
    """
    spec = _spec(name)
    radius = spec.hemisphere_radius
    preloads = PRELOAD_GRIDS[radius]
    drive = paper_drive(radius, float(preloads[0]), friction_coefficient=friction_coefficient,
                        contacts=spec.contacts)
    E_star, G_star = theory.contact_moduli(drive)
    mu = drive.friction_coefficient
    act = drive.actuator

    def presliding(force):
        return theory.presliding_displacement(force, radius, E_star, G_star, mu)

    def deformation(force):
        return theory.actuator_deformation(mu, force, act.stiffness, drive.runner_mass, act.mass)

    table = {"preload_N": preloads}
    if spec.contacts == 1:
        (force,) = theory.normal_forces(preloads, contacts=1)
        u_max, u_a = presliding(force), deformation(force)
        table.update(u_x_max_nm=u_max * _NM, u_x_a_nm=u_a * _NM, u_x_max_plus_u_x_a_nm=(u_max + u_a) * _NM)
    elif spec.name == "fig6a_closed_form":
        f1, f2 = theory.normal_forces(preloads, contacts=6)
        u1, u2 = presliding(f1), presliding(f2)
        table.update(u_x_max_1_nm=u1 * _NM, u_x_max_2_nm=u2 * _NM,
                     u_x_max_e_nm=theory.harmonic_combination(u1, u2) * _NM)
    else:
        f1, f2 = theory.normal_forces(preloads, contacts=6)
        a1, a2 = deformation(f1), deformation(f2)
        s1, s2 = presliding(f1) + a1, presliding(f2) + a2
        table.update(u_x_a_1_nm=a1 * _NM, u_x_a_2_nm=a2 * _NM, u_x_max_1_star_nm=s1 * _NM,
                     u_x_max_2_star_nm=s2 * _NM, u_x_max_e_star_nm=theory.harmonic_combination(s1, s2) * _NM)
    frame = pd.DataFrame(table)
    return frame[list(spec.columns)]


def curve_header(name: str, friction_coefficient: float = REFERENCE_FRICTION_COEFFICIENT) -> str:
    """The ``#`` comment block written above a reference-curve table (equations, parameters)."""
    spec = _spec(name)
    drive = paper_drive(spec.hemisphere_radius, 0.4, friction_coefficient=friction_coefficient,
                        contacts=spec.contacts)
    E_star, G_star = theory.contact_moduli(drive)
    act = drive.actuator
    lines = [
        f"Fig. {spec.figure} closed-form reference curves, Nguyen et al. (2018), Coatings 8, 62.",
        f"{spec.contacts} contact(s), R = {spec.hemisphere_radius * 1e3:g} mm, "
        f"mu = {drive.friction_coefficient:g} (assumption friction_coefficient_sections_4_1_and_5), "
        "preload grid of passmd.model.tables.PRELOAD_GRIDS.",
        f"E* = {E_star / 1e9:.6g} GPa, G* = {G_star / 1e9:.6g} GPa (Table 1, MDR convention); "
        f"k_p = {act.stiffness:.6g} N/m, m_a = {act.mass:.6g} kg (Table 2), m_r = {drive.runner_mass:g} kg.",
        *(f"{column}: {meaning}" for column, meaning in spec.columns.items()),
        "Generated by tools/make_reference_curves.py from passmd.model.theory; do not edit by hand.",
    ]
    return "".join(f"# {line}\n" for line in lines)


#: Significant digits written to the CSV files (the test compares with rtol = 1e-8).
CSV_FLOAT_FORMAT = "%.10g"


def write_reference_curves(directory: str | os.PathLike, *, overwrite: bool = False) -> list[Path]:
    """Write every table of :data:`CURVES` as ``<directory>/<name>.csv``, all or none
    (:func:`passmd.runtime.outputs.write_files`).

    Parameters
    ----------
    directory : path-like
        Target folder, created if missing. There is no default: the package never writes
        into its own installation (``tools/make_reference_curves.py`` passes the
        repository's ``passmd/data/reference/``).
    overwrite : bool
        Replace tables already there (default False: a file there raises
        :class:`~passmd.runtime.outputs.OutputExists`, a ``FileExistsError``, before any is written).

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    if directory is None:
        raise ValueError("directory = None is not allowed: give the folder to write the curves into")
    folder = Path(directory)
    targets = {name: folder / spec.filename for name, spec in CURVES.items()}
    folder.mkdir(parents=True, exist_ok=True)

    def writer(name):
        def write(tmp):
            with open(tmp, "w", encoding="utf-8", newline="") as fh:
                fh.write(curve_header(name))
                table = closed_form_curves(name)
                table.to_csv(fh, index=False, float_format=CSV_FLOAT_FORMAT, lineterminator="\n")
        return write

    write_files({target: writer(name) for name, target in targets.items()}, overwrite=overwrite)
    return list(targets.values())


def load_reference_curve(name: str, directory: str | os.PathLike | None = None) -> pd.DataFrame:
    """Read a committed reference-curve table (``#`` header lines skipped).

    Parameters
    ----------
    name : str
        File stem or file name of a table in :data:`CURVES`.
    directory : path-like, optional
        Folder holding it; default :data:`REFERENCE_DIR`.

    Read from a regular file of at most ``LIMITS["reference table"]`` bytes
    (:func:`passmd.runtime.inputs.read_bounded`).
    """
    spec = _spec(name)
    path = (Path(directory) if directory is not None else REFERENCE_DIR) / spec.filename
    if not path.is_file():
        raise FileNotFoundError(
            f"reference curve {path} is missing: run tools/make_reference_curves.py"
        )
    text = decode_text(read_bounded(path, "reference table"), str(path), "reference table")
    return pd.read_csv(io.StringIO(text), comment="#")


def tangential_stiffness_table(radii=(1.0e-3, 0.25e-3), preloads=None) -> pd.DataFrame:
    """Initial tangential stiffness 2aG* of each contact side, for several radii (closed form).

    Parameters
    ----------
    radii : sequence of float
        Hemisphere radii R in m (Table 2's radii by default).
    preloads : array-like, optional
        Preloads F_p in N; default the R = 0.25 mm grid (common to both radii).

    Returns
    -------
    pandas.DataFrame
        Columns ``radius_mm``, ``preload_N``, ``side`` (1: F_N1, 2: F_N2 of Eq. 1),
        ``normal_force_N``, ``tangential_stiffness_N_per_m``.
    """
    grid = np.asarray(PRELOAD_GRIDS[0.25e-3] if preloads is None else preloads, dtype=float)
    rows = []
    for radius in radii:
        E_star, G_star = theory.contact_moduli(paper_drive(radius, float(grid[0])))
        for side, forces in enumerate(theory.normal_forces(grid, contacts=6), start=1):
            stiffness = hertz.tangential_stiffness(forces, radius, E_star, G_star)
            rows.extend(
                {"radius_mm": radius * 1e3, "preload_N": p, "side": side, "normal_force_N": f,
                 "tangential_stiffness_N_per_m": k}
                for p, f, k in zip(grid, forces, stiffness, strict=True)
            )
    return pd.DataFrame(rows)
