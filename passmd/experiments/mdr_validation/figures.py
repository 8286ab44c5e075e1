"""The MDR-validation chapter's figures: the contact model against Hertz, Cattaneo–Mindlin and
Masing, its convergence in the number of springs and its cost (Sections 2–3, Eqs. 4–6).

The comparisons (``*_validation``, ``spring_picture``) compute one figure's data as a tidy
:class:`pandas.DataFrame` in SI units (the chapter converts to nm and mN); the regression tests lock
the same frames. Errors of tangential forces are stated relative to the sliding force μF_N. The
figure functions (``mdr_*``, the rows of :data:`FIGURES`) take a
:class:`~passmd.runtime.config.RunConfig` (the figures are the same on every profile), use one contact
of side 1 of the default drive (:func:`validation_contact`) and add the scalar columns their plots
need.

References: Hertz (1882); Cattaneo (1938), Mindlin (1949); Mindlin & Deresiewicz (1953),
Masing (1926); Popov, Friction 1 (2013) 41 (MDR, Eqs. 4–6 of the paper).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from passmd.experiments import FigureSpec
from passmd.experiments.model_numerics.facts import benchmark_results
from passmd.model import hertz
from passmd.model.mdr_contact import MDRContact
from passmd.model.parameters import Drive
from passmd.runtime.config import RunConfig
from passmd.runtime.validation import check_range

#: Spring counts of the convergence study (chapter panel e).
CONVERGENCE_SPRINGS = (10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)


def _contact(drive: Drive | None, springs=None) -> MDRContact:
    return MDRContact.for_drive(Drive() if drive is None else drive, side=0, springs=springs)


def spring_picture(drive: Drive | None = None, springs: int = 41, turn: float = 0.8,
                   back: float = 0.5) -> pd.DataFrame:
    """Fig. 4b from the model's own state: every spring after loading to ``turn`` and back.

    The discrete contact (side 1 of the drive, F_N1) is loaded from rest to u = turn·u_max
    and unloaded to u = (turn − back)·u_max, so the picture shows a sticking core, an
    annulus that slipped back and an outer rim still at its forward slip.

    Returns
    -------
    pandas.DataFrame
        :meth:`passmd.model.mdr_contact.MDRContact.spring_states` columns plus ``displacement_m``
        (the u shown) and ``turn_m`` (where the loading turned).
    """
    check_range("turn", turn, 0.0, 1.0, lower_open=True)
    check_range("back", back, 0.0, 2.0 * turn, lower_open=True)
    c = _contact(drive, springs)
    u_max = c.presliding
    c.path(np.linspace(0.0, turn * u_max, 50))
    c.path(np.linspace(turn * u_max, (turn - back) * u_max, 50))
    df = c.spring_states()
    df["displacement_m"] = c.displacement
    df["turn_m"] = turn * u_max
    return df


def normal_validation(drive: Drive | None = None, springs=(20, 100, 1000), points: int = 60) -> pd.DataFrame:
    """MDR normal force F(d) = Σ E*Δx (d − x_i²/R)⁺ against Hertz (4/3) E* √R d^{3/2}.

    Fixed spring grids (midpoints of N equal cells over |x| ≤ a_max, a_max the Hertz
    radius at twice the drive's F_N1) are pressed to depths d from d_max/points to d_max.
    Unlike the contact model, which re-solves d for its own F_N, the grid here does not
    know the answer: the test is Popov's rule R₁ = R/2 (Eq. 5) itself.

    Returns
    -------
    pandas.DataFrame
        ``indentation_m``, ``hertz_N`` and, per N, ``mdr_<N>_N`` and ``rel_error_<N>``.
    """
    drive = Drive() if drive is None else drive
    E_star, _ = drive.contact_moduli
    R = drive.hemisphere_radius
    F_max = 2.0 * float(drive.contact_layout.normal_forces[0])
    a_max = float(hertz.hertz_contact_radius(F_max, R, E_star))
    d = np.linspace(1.0, points, points) / points * a_max**2 / R
    out = {"indentation_m": d, "hertz_N": 4.0 / 3.0 * E_star * np.sqrt(R) * d**1.5}
    for n in springs:
        dx = 2.0 * a_max / n
        x = -a_max + (np.arange(n) + 0.5) * dx
        deflection = np.maximum(d[:, None] - x[None, :] ** 2 / R, 0.0)
        force = E_star * dx * deflection.sum(axis=1)
        out[f"mdr_{n}_N"] = force
        out[f"rel_error_{n}"] = force / out["hertz_N"] - 1.0
    return pd.DataFrame(out)


def virgin_validation(drive: Drive | None = None, springs=(20, 100, 1000), points: int = 121) -> pd.DataFrame:
    """Virgin tangential loading from rest to 1.2 u_max: exact and discrete vs Cattaneo–Mindlin.

    Returns
    -------
    pandas.DataFrame
        ``u_m``, ``cattaneo_mindlin_N`` (:func:`passmd.model.hertz.cattaneo_mindlin_force`),
        ``exact_N``, ``discrete_<N>_N``, ``slip_share_exact``.
    """
    exact = _contact(drive)
    u = np.linspace(0.0, 1.2 * exact.presliding, points)
    out = {
        "u_m": u,
        "cattaneo_mindlin_N": hertz.cattaneo_mindlin_force(
            u, exact.normal_force, exact.presliding, exact.friction_coefficient
        ),
        "slip_share_exact": exact.slip_share(u),
        "exact_N": exact.path(u),
    }
    for n in springs:
        out[f"discrete_{n}_N"] = _contact(drive, n).path(u)
    return pd.DataFrame(out)


def hysteresis_path(amplitude: float = 0.9, minor_top: float = 0.4, minor_bottom: float = -0.2,
                    per_leg: int = 60) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The chapter's loop in fractions of u_max: (displacements, segment labels, turning points).

    0 → A → −A → B → C → B → A with A = ``amplitude``, B = ``minor_top``,
    C = ``minor_bottom``: a major loop with a minor loop B–C–B nested in its rising branch.
    Segment k runs from turning point k to k + 1.
    """
    turns = np.array([0.0, amplitude, -amplitude, minor_top, minor_bottom, minor_top, amplitude])
    if not (-amplitude < minor_bottom < minor_top < amplitude <= 1.0):
        raise ValueError(
            f"minor loop ({minor_bottom!r}, {minor_top!r}) is out of range: must satisfy "
            f"-amplitude < minor_bottom < minor_top < amplitude <= 1 (amplitude = {amplitude!r})"
        )
    us, seg = [], []
    for k, (a, b) in enumerate(zip(turns[:-1], turns[1:], strict=True)):
        us.append(np.linspace(a, b, per_leg + 1)[1:])
        seg.append(np.full(per_leg, k))
    return np.concatenate(us), np.concatenate(seg), turns


#: Turning point each segment of :func:`hysteresis_path` starts its Masing branch from
#: (None: the virgin curve). The last segment B → A resumes the branch from −A: the
#: minor loop B–C–B closed at B and was wiped out (Mindlin–Deresiewicz memory rule).
HYSTERESIS_BRANCH_ORIGIN = (None, 1, 2, 3, 4, 2)


def masing_reference(u, segment, turns, normal_force, presliding, friction_coefficient):
    """Mindlin–Deresiewicz/Masing solution along :func:`hysteresis_path`, from passmd.model.theory only.

    Parameters
    ----------
    u, segment : numpy.ndarray
        Displacements (m) and their segment index (segment k runs from turns[k] to turns[k+1]).
    turns : numpy.ndarray
        The seven turning points 0, A, −A, B, C, B, A in m.
    normal_force, presliding, friction_coefficient : float
        F_N (N), u_max (m, Eq. 7) and μ.
    """
    args = (normal_force, presliding, friction_coefficient)

    def branch(k, x):
        origin = HYSTERESIS_BRANCH_ORIGIN[k]
        if origin is None:
            return hertz.cattaneo_mindlin_force(x, *args)
        direction = np.sign(turns[k + 1] - turns[k])
        return hertz.masing_branch_force(x, turns[origin], f_turn[origin], direction, *args)

    f_turn = [0.0]
    for k in range(len(turns) - 1):  # force at each turning point, from the branch arriving there
        f_turn.append(float(branch(k, turns[k + 1])))
    out = np.empty_like(u, dtype=float)
    for k in range(len(turns) - 1):
        sel = segment == k
        out[sel] = branch(k, u[sel])
    return out


def hysteresis_validation(drive: Drive | None = None, springs: int = 1000, **path) -> pd.DataFrame:
    """A major loop with a nested minor loop: exact and discrete vs Masing.

    Returns
    -------
    pandas.DataFrame
        ``step``, ``segment``, ``u_m``, ``masing_N`` (:func:`masing_reference`),
        ``exact_N``, ``discrete_<N>_N``.
    """
    exact = _contact(drive)
    fractions, segment, turn_fractions = hysteresis_path(**path)
    u_max = exact.presliding
    u, turns = fractions * u_max, turn_fractions * u_max
    return pd.DataFrame(
        {
            "step": np.arange(u.size),
            "segment": segment,
            "u_m": u,
            "masing_N": masing_reference(u, segment, turns, exact.normal_force, u_max,
                                         exact.friction_coefficient),
            "exact_N": exact.path(u),
            f"discrete_{springs}_N": _contact(drive, springs).path(u),
        }
    )


def convergence_path(seed: int = 2018, reversals: int = 40, per_leg: int = 20) -> np.ndarray:
    """Random path in fractions of u_max: nested reversals, and full sliding now and then.

    Turning points alternate in sign-ish random amplitudes up to 2.5 u_max (beyond 2 u_max
    a swing ends in full sliding), shrinking geometrically within each of four bursts so
    that minor loops nest.
    """
    rng = np.random.default_rng(seed)
    bursts = np.array_split(np.arange(reversals), 4)
    turns = [0.0]
    for burst in bursts:
        amp = 2.5 * rng.uniform(0.3, 1.0) * 0.8 ** np.arange(burst.size)
        sign = rng.choice([-1.0, 1.0])
        turns += list(sign * (-1.0) ** np.arange(burst.size) * amp * rng.uniform(0.6, 1.0, burst.size))
    turns = np.array(turns)
    return np.concatenate([np.linspace(a, b, per_leg + 1)[1:] for a, b in zip(turns[:-1], turns[1:],
                                                                                strict=True)])


def convergence_validation(drive: Drive | None = None, springs=CONVERGENCE_SPRINGS,
                           seed: int = 2018) -> pd.DataFrame:
    """Largest |T_discrete − T_exact| / μF_N along :func:`convergence_path` for each N.

    Returns
    -------
    pandas.DataFrame
        ``springs``, ``max_error_rel``, ``rms_error_rel``.
    """
    exact = _contact(drive)
    u = convergence_path(seed) * exact.presliding
    reference = exact.path(u)
    rows = []
    for n in springs:
        diff = (_contact(drive, int(n)).path(u) - reference) / exact.sliding_force
        rows.append({"springs": int(n), "max_error_rel": float(np.max(np.abs(diff))),
                     "rms_error_rel": float(np.sqrt(np.mean(diff**2)))})
    return pd.DataFrame(rows)


def fitted_order(errors: pd.DataFrame, column: str = "max_error_rel", min_springs: int = 100) -> float:
    """Convergence order p of error ∝ N^(−p): least-squares slope on log–log axes (N ≥ min_springs)."""
    sel = errors["springs"] >= min_springs
    slope = np.polyfit(np.log(errors.loc[sel, "springs"]), np.log(errors.loc[sel, column]), 1)[0]
    return float(-slope)


#: Spring counts of the normal and virgin-loading comparisons.
VALIDATION_SPRINGS = (20, 100, 1000)
#: Spring count of the discrete contact in the hysteresis comparison.
HYSTERESIS_SPRINGS = 1000
#: Names of the turning points 1–4 of :func:`hysteresis_path`.
HYSTERESIS_TURNS = ("A", "−A", "B", "C")


def validation_contact(springs: int | None = None) -> MDRContact:
    """The chapter's contact: side 1 of the default drive (exact, or ``springs`` discrete springs)."""
    return MDRContact.for_drive(Drive(), side=0, springs=springs)


def mdr_springs(config: RunConfig) -> pd.DataFrame:
    """:func:`spring_picture` plus the exact contact's
    indentation (m),
    the hemisphere radius (m) and μ."""
    drive, exact = Drive(), validation_contact()
    df = spring_picture(drive)
    df["indentation_m"] = exact.indentation
    df["hemisphere_radius_m"] = drive.hemisphere_radius
    df["friction_coefficient"] = drive.friction_coefficient
    return df


def mdr_normal(config: RunConfig) -> pd.DataFrame:
    """:func:`normal_validation` for
    :data:`VALIDATION_SPRINGS`."""
    return normal_validation(Drive(), springs=VALIDATION_SPRINGS)


def mdr_virgin(config: RunConfig) -> pd.DataFrame:
    """:func:`virgin_validation` plus ``sliding_force_N``
    (μF_N)."""
    df = virgin_validation(Drive(), springs=VALIDATION_SPRINGS)
    df["sliding_force_N"] = validation_contact().sliding_force
    return df


def mdr_hysteresis(config: RunConfig) -> pd.DataFrame:
    """:func:`hysteresis_validation` plus ``turn``: the
    name of each
    turning point (:data:`HYSTERESIS_TURNS`) on the first row that reaches it, else ``""``."""
    df = hysteresis_validation(Drive(), springs=HYSTERESIS_SPRINGS)
    u_max = validation_contact().presliding
    _, _, turns = hysteresis_path()
    df["turn"] = ""
    for name, t in zip(HYSTERESIS_TURNS, turns[1:5], strict=True):
        first = df.index[np.isclose(df["u_m"], t * u_max, rtol=1e-12, atol=0)][0]
        df.loc[first, "turn"] = name
    return df


def mdr_convergence(config: RunConfig) -> pd.DataFrame:
    """:func:`convergence_validation` plus the fitted
    order and its line.

    ``fitted_order`` is :func:`fitted_order` (N ≥ 100);
    ``fit_rel`` the
    least-squares power law of ``max_error_rel`` over those N (NaN below).
    """
    df = convergence_validation(Drive())
    fit = df["springs"] >= 100
    coef = np.polyfit(np.log(df.loc[fit, "springs"]), np.log(df.loc[fit, "max_error_rel"]), 1)
    df["fit_rel"] = np.where(fit, np.exp(np.polyval(coef, np.log(df["springs"]))), np.nan)
    df["fitted_order"] = fitted_order(df)
    return df


def mdr_cost(config: RunConfig) -> pd.DataFrame:
    """Cost per contact update from ``benchmarks/bench_contact.py``'s results file, with the
    ``repeats`` and ``numba`` version it was measured with."""
    bench = benchmark_results("contact")
    df = pd.DataFrame(bench["rows"])
    df["repeats"] = bench["meta"]["repeats"]
    df["numba"] = bench["meta"]["numba"]
    return df


#: The chapter's rows of the figure table.
FIGURES = (
    FigureSpec("mdr_springs", "Springs of the discrete MDR contact after loading and unloading (Fig. 4b)",
               "mdr_validation", mdr_springs, "mdr:plot_springs"),
    FigureSpec("mdr_normal", "MDR normal force against Hertz", "mdr_validation", mdr_normal,
               "mdr:plot_normal"),
    FigureSpec("mdr_virgin", "Virgin tangential loading against Cattaneo-Mindlin", "mdr_validation",
               mdr_virgin, "mdr:plot_virgin"),
    FigureSpec("mdr_hysteresis", "Major and nested minor hysteresis loop against Masing", "mdr_validation",
               mdr_hysteresis, "mdr:plot_hysteresis"),
    FigureSpec("mdr_convergence", "Deviation of the discrete MDR contact from the exact one against N",
               "mdr_validation", mdr_convergence, "mdr:plot_convergence"),
    FigureSpec("mdr_cost", "Cost per contact update against the number of springs (benchmark)",
               "mdr_validation", mdr_cost, "mdr:plot_cost"),
)
