"""The ledger's joint reading as a drive file and command-line options.

A point of the ledger's space (:mod:`passmd.ledger.readings`) sets what the paper leaves open, each
section on its own. Three of its axes are properties of the drive — the fly-back rule (``[amplifier]
flyback``), the actuator damping ratio ζ (``[actuator] damping_ratio``) and μ (``friction_coefficient``)
— the others belong to a protocol (how A_c is read off the runs, the drive frequency of Section 4.1
and of the force runs, Eq. 15 when t_s does not fit). The file's keys hold the reading of
:data:`DRIVE_SECTION` (Section 4.1: the paper's drive at R = 1 mm, 0.4 N of Figs. 5–6); its header
gives, for each section, the command that runs its simulations under the reading, with the options
that set the protocol axes and the drive axes where the section's reading differs from the file's
(μ = 0.2, which Section 4.2 states, included). ``passmd ledger --write-drive FILE`` writes the joint
reading of a ledger run; :func:`reading_from_baseline` recovers it from a baseline CSV, so that the
shipped ``passmd/data/drives/joint_reading.toml`` is checked against the paper-profile baseline.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from passmd.ledger import readings
from passmd.ledger.baseline import load_baseline_states
from passmd.ledger.claims import load_claims
from passmd.model.drive_file import drive_toml
from passmd.model.parameters import Drive
from passmd.model.tables import actuator_for_radius

__all__ = ["DRIVE_AXES", "DRIVE_SECTION", "SECTION_COMMANDS", "joint_drive", "joint_drive_file",
           "reading_from_baseline", "section_reading"]

#: Axes that are properties of the drive: axis key -> (drive-file key, command-line option).
DRIVE_AXES = {"flyback": ("amplifier.flyback", "--flyback"),
              "damping_ratio": ("actuator.damping_ratio", None),
              "friction_coefficient": ("friction_coefficient", "--mu")}
#: The section whose reading the drive file's keys hold.
DRIVE_SECTION = "4.1"
#: Per section: the command that runs its simulations and its protocol axes as (axis key, option,
#: display unit); no option (None): the command line does not offer the reading (``run --waveform
#: optimized`` refuses a frequency at which Eq. 15's settling time does not fit, so ``short_period`` is
#: the library's).
SECTION_COMMANDS = {
    "4.1": ("critical-amplitude", (("ac_protocol", "--protocol", ""),
                                   ("drive_frequency_s4", "--frequency", "Hz"))),
    "4.2": ("force", (("force_frequency", "--frequency", "Hz"),)),
    "5": ("run --waveform optimized", (("short_period", None, ""),)),
}


def section_reading(point: Mapping, section: str) -> dict:
    """``{axis key: value}`` of a section at a point of the space (``{free axis: value}``): the point's
    values on the free axes of that section and the paper-scoped ones, the value a section states where
    it states one, every other axis at its default. A plain reading (axis keys) is returned as it is,
    completed with the defaults."""
    if all(isinstance(k, str) for k in point):
        return {**readings.default_reading(), **point}
    out = readings.default_reading()
    for (key, sec), value in point.items():
        if sec in ("", section):
            out[key] = value
    for key, value, _ in readings.SECTIONS[section].stated:
        out[key] = value
    return out


def joint_drive(reading: Mapping, hemisphere_radius: float = 1.0e-3, preload: float = 0.4) -> Drive:
    """The paper's drive (Tables 1–2 at ``hemisphere_radius``, ``preload``) with the drive axes of a point
    (its :data:`DRIVE_SECTION`'s reading) or of a plain reading (an axis it leaves out keeps its default)."""
    full = section_reading(reading, DRIVE_SECTION)
    actuator = actuator_for_radius(hemisphere_radius, damping_ratio=float(full["damping_ratio"]))
    drive = Drive(hemisphere_radius=hemisphere_radius, preload=preload, actuator=actuator,
                  friction_coefficient=float(full["friction_coefficient"]))
    return replace(drive, amplifier=replace(drive.amplifier, flyback=full["flyback"]))


def _shown(value, unit: str = "") -> str:
    return f"{value:g}{unit}" if isinstance(value, float) else str(value)


def _commands(point: Mapping) -> list[str]:
    """The command lines that run each section under the point, one per section."""
    file_reading = section_reading(point, DRIVE_SECTION)
    lines = []
    for section, (command, options) in SECTION_COMMANDS.items():
        mine = section_reading(point, section)
        parts, notes = [], []
        for key, option, unit in options:
            if option is None:
                notes.append(f"{readings.AXES[key].label} = {_shown(mine[key])}, "
                             "passmd.model.optimized_waveform")
            else:
                parts.append(f"{option} {_shown(mine[key], unit)}")
        for key, (_, option) in DRIVE_AXES.items():
            applies = set(readings.AXES[key].tables) & set(readings.SECTIONS[section].tables) or any(
                k == key for k, _, _ in readings.SECTIONS[section].stated)
            if applies and option and mine[key] != file_reading[key]:
                parts.append(f"{option} {_shown(mine[key])}")
        note = f" (no option: {'; '.join(notes)})" if notes else ""
        lines.append(f"{readings.SECTIONS[section].label}: passmd {command} --drive FILE"
                     + "".join(f" {p}" for p in parts) + note)
    return lines


def joint_drive_file(point: Mapping, profile: str, hemisphere_radius: float = 1.0e-3,
                     preload: float = 0.4) -> str:
    """The text of a drive file holding the drive axes of a point's :data:`DRIVE_SECTION` reading
    (:func:`joint_drive`), each with the reading as its source, and in its header, per section, the
    command and options that run it under the point (:data:`SECTION_COMMANDS`);
    :func:`passmd.model.drive_file.load_drive` reads it back to :func:`joint_drive`."""
    full = section_reading(point, DRIVE_SECTION)
    drive = joint_drive(point, hemisphere_radius, preload)
    where = f"the ledger's joint reading ({profile} profile), {readings.SECTIONS[DRIVE_SECTION].label}"
    sources = {key: f"{where}: {readings.AXES[axis].label} = {readings.AXES[axis].show(full[axis])}"
               for axis, (key, _) in DRIVE_AXES.items()}
    described = (readings.describe_point(point) if not all(isinstance(k, str) for k in point)
                 else readings.describe(full))
    header = [f"# The replication ledger's joint reading ({profile} profile): {described}.",
              f"# The keys below hold its drive axes for {readings.SECTIONS[DRIVE_SECTION].label}; each "
              "section runs under it with:"]
    header += [f"#   {line}" for line in _commands(point)]
    header.append("# Written by `passmd ledger --profile " + profile + " --write-drive FILE`.")
    text = drive_toml(drive, sources, title="passmd drive file: the paper's drive under the ledger's "
                      "joint reading", damping_ratio=float(full["damping_ratio"]))
    return "\n".join(header) + "\n" + text


def _parts(claim: Mapping) -> dict[str, tuple[str, object]]:
    """Each value of an axis a claim depends on, in words (``"fly-back rule = fixed"``) -> (axis key,
    value)."""
    return {readings.describe({key: v}, only_changed=False): (key, v)
            for key in readings.applicable(claim) for v in readings.AXES[key].values()}


def reading_from_baseline(path, claims=None) -> dict:
    """The joint reading a baseline CSV records (:func:`passmd.ledger.baseline.load_baseline_states`), as
    a point ``{free axis: value}``: the union of each claim's projection of it onto its section's free
    axes; free axes no claim depends on keep their default. ``claims`` (default claims.csv) gives each
    claim's section and axes.

    Raises
    ------
    ValueError
        The baseline records no states, a projection names no value of an axis its claim depends on, or
        two projections disagree.
    """
    states = load_baseline_states(path)
    if not states:
        raise ValueError(f"{path}: the baseline records no joint reading (no states column)")
    rows = (load_claims() if claims is None else claims).set_index("id")
    point = readings.default_point(readings.declared_free_axes())
    seen: dict = {}
    for claim, record in states.items():
        text = record["joint"]
        if text == "defaults" or claim not in rows.index:
            continue
        row = {**rows.loc[claim], "id": claim}
        parts = _parts(row)
        for part in text.split("; "):
            if part not in parts:
                raise ValueError(f"{path}: claim {claim}'s joint reading {part!r} is no value of an axis it "
                                 "depends on")
            key, value = parts[part]
            free = readings.free_axes((key,), readings.section_of(row))[0]
            if seen.setdefault(free, value) != value:
                raise ValueError(f"{path}: the claims' joint readings disagree on "
                                 f"{readings.free_label(free)}")
            point[free] = value
    return point
