"""Plots of the numerics section: time-step convergence and the rigid Coulomb limit."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.lines import Line2D
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter, NullLocator

from passmd.solver.steps import CONVERGED_ACCURACY

__all__ = ["CONVERGED_STEP_NM", "STEP_CONTROL_STYLES", "plot_actuator_mass", "plot_convergence",
           "plot_coulomb_limit", "plot_scaling"]

#: Position error drawn as the convergence target (:data:`passmd.solver.steps.CONVERGED_ACCURACY`) (nm).
CONVERGED_STEP_NM = CONVERGED_ACCURACY * 1e9


#: Legend name of each step control of the convergence figure
#: (:data:`passmd.experiments.model_numerics.figures.STEP_CONTROLS`) and its line style and marker.
STEP_CONTROL_STYLES = {
    "controlled": ("error-controlled (default)", "-", "o"),
    "adaptive": ("explicit adaptive", "--", "s"),
    "quasi-static": ("quasi-static actuator", "-.", "^"),
    "fixed": ("fixed fine step", ":", "x"),
}


def plot_convergence(df: pd.DataFrame):
    """|position error| after the run against the step refinement: one colour per configuration,
    one line style and marker per step control (:data:`STEP_CONTROL_STYLES`)."""
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    colours = {label: f"C{i}" for i, label in enumerate(df["configuration"].unique())}
    for (label, control), g in df.groupby(["configuration", "step_control"], sort=False):
        g = g[g["error_m"] != 0]
        _, style, marker = STEP_CONTROL_STYLES[control]
        ax.loglog(g["resolution"], np.abs(g["error_m"]) * 1e9, ls=style, marker=marker, color=colours[label],
                  lw=2.0 if control == "controlled" else 1.0, ms=5)
    r = np.array(sorted(df["resolution"].unique()))
    ax.loglog(r, 0.02 * r**-2.0, color="grey", ls=(0, (1, 3)), lw=1)
    ax.loglog(r, 0.02 * r**-3.0, color="grey", ls=(0, (5, 1, 1, 1)), lw=1)
    ax.axhline(CONVERGED_STEP_NM, color="grey", lw=0.8, ls="--")
    ax.set_xticks(r, [f"{v:g}" for v in r])
    ax.xaxis.set_minor_locator(NullLocator())
    ax.set_xlabel("step refinement (1 = default; error-controlled: tolerance ÷ refinement⁴)")
    ax.set_ylabel("|position error| after 3 periods (nm)")
    handles = [Line2D([], [], color=c, lw=2, label=label) for label, c in colours.items()]
    handles += [Line2D([], [], color="k", ls=STEP_CONTROL_STYLES[c][1], marker=STEP_CONTROL_STYLES[c][2],
                       lw=2.0 if c == "controlled" else 1.0, label=STEP_CONTROL_STYLES[c][0])
                for c in STEP_CONTROL_STYLES if c in set(df["step_control"])]
    handles += [Line2D([], [], color="grey", ls=(0, (1, 3)), label="slope −2"),
                Line2D([], [], color="grey", ls=(0, (5, 1, 1, 1)), label="slope −3")]
    ax.legend(handles=handles, fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    fig.tight_layout()
    return fig


def plot_coulomb_limit(df: pd.DataFrame):
    """|simulated − Coulomb step| against the factor on the contact moduli, with the expected slope."""
    fig, ax = plt.subplots(figsize=(6.4, 4))
    for label, g in df.groupby("configuration", sort=False):
        ax.loglog(g["scale"], np.abs(g["difference_m"]) * 1e9, "o-",
                  label=f"{label} (rate {float(g['rate'].iloc[0]):.2f})")
    k = np.array(sorted(df["scale"].unique()))
    first = df[df["scale"] == k[0]]
    ref = float(np.abs(first["difference_m"]).max() * 1e9)
    expected = float(df["expected_rate"].iloc[0])
    ax.loglog(k, ref * (k / k[0]) ** -expected, "k:",
              label=f"slope −{expected:.2f} (presliding $\\propto k^{{-2/3}}$)")
    ax.set_xlabel("factor k on the contact moduli E*, G*")
    ax.set_ylabel("|simulated step − Coulomb step| (nm)")
    ax.legend(fontsize=7)
    return fig


def plot_actuator_mass(df: pd.DataFrame):
    """The actuator-mass study against m_a (log axis): the steady-state A_c under each fly-back rule with
    Eq. 12 and the band of the ledger's tolerance around it (left); the actuator's natural frequencies
    and the runner's ringing, with the paper's 110 kHz (middle); the saw-tooth's steady velocity over
    f, i.e. the step per period, at each frequency (right). Dotted verticals: Table 2's printed m_a and
    a ruby hemisphere's mass."""
    per_mass = df.drop_duplicates("actuator_mass").sort_values("actuator_mass")
    m = per_mass["actuator_mass_ug"]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
    ax = axes[0]
    eq12, tolerance = per_mass["eq12_nm"], float(per_mass["eq12_tolerance_rel"].iloc[0])
    ax.fill_between(m, (1 - tolerance) * eq12, (1 + tolerance) * eq12, color="0.85",
                    label=f"Eq. 12 ± {100 * tolerance:g} % (the ledger's tolerance)")
    ax.plot(m, eq12, "k--", lw=1, label="Eq. 12")
    for rule, marker in (("slew", "o"), ("fixed", "s")):
        ax.plot(m, per_mass[f"critical_amplitude_{rule}_nm"], marker=marker, ms=5, lw=1,
                label=f"simulated, {rule} fly-back")
    ax.set(xscale="log", xlabel="actuator mass m_a (µg)", ylabel="steady-state A_c (nm)",
           title="critical amplitude (six contacts, 0.4 N)", ylim=(0, None))
    ax.legend(fontsize=7)
    ax = axes[1]
    ax.plot(m, per_mass["actuator_frequency_Hz"] / 1e3, "o-", ms=4, lw=1, label="actuator, √(k_p/m_a)/2π")
    for side, style in ((1, "--"), (2, ":")):
        ax.plot(m, per_mass[f"actuator_on_contact_{side}_Hz"] / 1e3, ls=style, lw=1,
                label=f"actuator on its contact, side {side}")
    ax.plot(m, per_mass["ringing_frequency_Hz"] / 1e3, "s-", ms=4, lw=1, label="runner's micro-vibration")
    ax.axhline(110.0, color="tab:red", lw=0.8, label="110 kHz (Section 5.2's limit)")
    ax.set(xscale="log", yscale="log", xlabel="actuator mass m_a (µg)", ylabel="frequency (kHz)",
           title="ringing frequencies")
    ax.legend(fontsize=7, loc="center left")
    ax = axes[2]
    for f, part in df.groupby("frequency_Hz", sort=True):
        part = part.sort_values("actuator_mass")
        ax.plot(part["actuator_mass_ug"], part["velocity_m_per_s"] / f * 1e9, marker=".", ms=6, lw=1,
                label=f"{f / 1e3:g} kHz")
    ax.axhline(0.0, color="grey", lw=0.5)
    ax.set(xscale="log", xlabel="actuator mass m_a (µg)", ylabel="steady velocity / f (nm per period)",
           title="saw-tooth at the full stroke")
    ax.legend(fontsize=7, title="frequency", title_fontsize=7)
    for ax in axes:
        for flag, label in (("printed", "Table 2"), ("hemisphere", "ruby hemisphere")):
            mass = float(per_mass.loc[per_mass[flag].astype(bool), "actuator_mass_ug"].iloc[0])
            ax.axvline(mass, color="grey", ls=":", lw=0.8)
            ax.annotate(label, (mass, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -3),
                        textcoords="offset points", rotation=90, fontsize=7, va="top", ha="left",
                        color="grey")


def plot_scaling(data: dict):
    """The stored scaling measurement (``benchmarks/bench_scaling.py``): cost per 100 Hz period against
    the contact states integrated, CPU time per simulated millisecond against the drive frequency (with
    the share of fine steps), and a cold sweep's wall time against its points."""
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(10.5, 3.4))
    contacts = pd.DataFrame(data["contacts"])
    for shared, style, label in ((False, "o-", "a state per contact"), (True, "s--", "a state per side")):
        rows = contacts[contacts["shared_side_state"] == shared]
        ax1.loglog(rows["contacts"], rows["ms_per_100Hz_period"], style, label=label)
    ax1.set_xticks(sorted(contacts["contacts"].unique()))
    ax1.set_xticklabels([str(n) for n in sorted(contacts["contacts"].unique())])
    ax1.xaxis.set_minor_locator(NullLocator())
    ax1.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax1.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax1.yaxis.set_minor_formatter(NullFormatter())
    ax1.set_xlabel("contacts")
    ax1.set_ylabel("CPU ms per 100 Hz period")
    ax1.set_title("(a) contacts, flexible actuators", fontsize=9)
    ax1.legend(fontsize=7)
    freq = pd.DataFrame(data["frequency"])
    ax2.loglog(freq["frequency_Hz"], freq["ms_per_simulated_ms"], "o-", label="CPU ms per simulated ms")
    ax2.set_xlabel("drive frequency (Hz)")
    ax2.set_ylabel("CPU ms per simulated ms")
    ax2.set_title("(b) frequency, six contacts", fontsize=9)
    twin = ax2.twinx()
    twin.semilogx(freq["frequency_Hz"], 100 * freq["fine_share"], "x:", color="C1", label="fine steps (%)")
    twin.set_ylabel("fine steps (% of steps)", color="C1")
    twin.set_ylim(0, 105)
    sweep = data["sweep"]
    points = np.asarray(sweep["points"], float)
    ax3.plot(points, sweep["wall_s"], "o", label="measured")
    ax3.plot(points, sweep["start_s"] + sweep["s_per_point"] * points, "k:",
             label=f"{1e3 * sweep['s_per_point']:.1f} ms/point + {sweep['start_s']:.2f} s")
    ax3.set_xlabel("sweep points (cold cache)")
    ax3.set_ylabel("wall time (s)")
    ax3.set_title(f"(c) settled steps, {sweep['workers']} workers", fontsize=9)
    ax3.legend(fontsize=7)
    fig.suptitle("stored measurement: benchmarks/bench_scaling.py (passmd/data/benchmarks/scaling.json)",
                 fontsize=8)
    fig.tight_layout()
    return fig
