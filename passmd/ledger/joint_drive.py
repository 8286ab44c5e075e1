"""The ledger's joint reading as a drive file and command-line options.

A reading (:mod:`passmd.ledger.readings`) sets what the paper leaves open. Three of its axes are
properties of the drive — the fly-back rule (``[amplifier] flyback``), the actuator damping ratio
ζ (``[actuator] damping_ratio``) and μ of Sections 4.1 and 5 (``friction_coefficient``) — and are
written into the drive file; the others belong to a protocol (how A_c is read off the runs, the
drive frequency of Section 4.1 and of the force runs) and become options of the commands that run
it, listed in the file's header. ``passmd ledger --write-drive FILE`` writes the joint reading
of a ledger run; :func:`reading_from_baseline` recovers it from a baseline CSV, so that the shipped
``passmd/data/drives/joint_reading.toml`` is checked against the paper-profile baseline.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from passmd.ledger import readings
from passmd.ledger.baseline import load_baseline_states
from passmd.model.drive_file import drive_toml
from passmd.model.parameters import Drive
from passmd.model.tables import actuator_for_radius

__all__ = ["DRIVE_AXES", "OPTION_AXES", "joint_drive", "joint_drive_file", "reading_from_baseline"]

#: Axes that are properties of the drive: axis key -> drive-file key.
DRIVE_AXES = {"flyback": "amplifier.flyback", "damping_ratio": "actuator.damping_ratio",
              "friction_coefficient": "friction_coefficient"}
#: Axes that belong to a protocol: axis key -> (command, option, display unit) that sets it; no
#: option (None): the command line does not offer the reading (``run --waveform optimized`` refuses
#: a frequency at which Eq. 15's settling time does not fit, so ``short_period`` is the library's).
OPTION_AXES = {"ac_protocol": ("critical-amplitude", "--protocol", ""),
               "drive_frequency_s4": ("critical-amplitude", "--frequency", "Hz"),
               "force_frequency": ("force", "--frequency", "Hz"),
               "short_period": ("run --waveform optimized", None, "")}


def joint_drive(reading: Mapping, hemisphere_radius: float = 1.0e-3, preload: float = 0.4) -> Drive:
    """The paper's drive (Tables 1–2 at ``hemisphere_radius``, ``preload``) with the drive axes of
    ``reading`` (:data:`DRIVE_AXES`; an axis the reading leaves out keeps its default)."""
    full = {**readings.default_reading(), **reading}
    actuator = actuator_for_radius(hemisphere_radius, damping_ratio=float(full["damping_ratio"]))
    drive = Drive(hemisphere_radius=hemisphere_radius, preload=preload, actuator=actuator,
                  friction_coefficient=float(full["friction_coefficient"]))
    return replace(drive, amplifier=replace(drive.amplifier, flyback=full["flyback"]))


def _commands(full: Mapping) -> list[str]:
    """The command lines that set the protocol axes of ``full``, one per command."""
    lines: dict[str, list[str]] = {}
    for key, (command, option, unit) in OPTION_AXES.items():
        value = full[key]
        shown = f"{value:g}{unit}" if isinstance(value, float) else str(value)
        if option is None:
            lines.setdefault(command, []).append(
                f"(no option: {readings.AXES[key].label} = {shown}, passmd.model.optimized_waveform)")
        else:
            lines.setdefault(command, []).append(f"{option} {shown}")
    return [f"passmd {command} --drive FILE {' '.join(parts)}" for command, parts in lines.items()]


def joint_drive_file(reading: Mapping, profile: str, hemisphere_radius: float = 1.0e-3,
                     preload: float = 0.4) -> str:
    """The text of a drive file holding ``reading``'s drive axes (:func:`joint_drive`), each with the
    reading as its source, and in its header the options that set the protocol axes
    (:data:`OPTION_AXES`); :func:`passmd.model.drive_file.load_drive` reads it back to
    :func:`joint_drive`."""
    full = {**readings.default_reading(), **reading}
    drive = joint_drive(full, hemisphere_radius, preload)
    where = f"the ledger's joint reading ({profile} profile)"
    sources = {key: f"{where}: {readings.AXES[axis].label} = {readings.AXES[axis].show(full[axis])}"
               for axis, key in DRIVE_AXES.items()}
    header = [f"# The replication ledger's joint reading ({profile} profile): "
              f"{readings.describe(full)}.",
              "# The drive axes of the reading are the keys below; its protocol axes are options:"]
    header += [f"#   {line}" for line in _commands(full)]
    header.append("# Written by `passmd ledger --profile " + profile + " --write-drive FILE`.")
    text = drive_toml(drive, sources, title="passmd drive file: the paper's drive under the ledger's "
                      "joint reading", damping_ratio=float(full["damping_ratio"]))
    return "\n".join(header) + "\n" + text


def _parts() -> dict[str, tuple[str, object]]:
    """Each axis value in words (``"fly-back rule = fixed"``) -> (axis key, value)."""
    return {readings.describe({a.key: v}, only_changed=False): (a.key, v)
            for a in readings.AXES.values() for v in a.values()}


def reading_from_baseline(path) -> dict:
    """The joint reading a baseline CSV records (:func:`passmd.ledger.baseline.load_baseline_states`):
    the union of each claim's projection of it; axes no claim depends on keep their default.

    Raises
    ------
    ValueError
        The baseline records no states, a projection names no declared axis value, or two
        projections disagree.
    """
    states = load_baseline_states(path)
    if not states:
        raise ValueError(f"{path}: the baseline records no joint reading (no states column)")
    parts, reading = _parts(), {}
    for claim, record in states.items():
        text = record["joint"]
        for part in ([] if text == "defaults" else text.split("; ")):
            if part not in parts:
                raise ValueError(f"{path}: claim {claim}'s joint reading {part!r} is no declared axis value")
            key, value = parts[part]
            if reading.setdefault(key, value) != value:
                raise ValueError(f"{path}: the claims' joint readings disagree on {readings.AXES[key].label}")
    return {**readings.default_reading(), **reading}
