"""Generated input files and ``--vary`` specifications: whatever a user writes, one clean outcome.

Contract (README, "Reliability"): a drive file (a TOML document with any keys, types, units,
layout and encoding), a measurement file (any header, separator, cells, line endings and
encoding) and a ``--vary`` specification end in

* exit 0 with a finite result (``--json``: every number finite), or with every check passed
  (the fit or the map, stood in for here, is reached), or
* exit 2 with exactly one line on stderr naming the file (the option, for ``--vary``) and
  what in it is refused,

never a traceback, an internal error, a RuntimeWarning or another status.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from unittest import mock

import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st
from test_bad_inputs import UNITS, _finite_json, _Reached, _reached, run_main

from passmd.cli.commands.sweep import AXES
from passmd.model.drive_file import DRIVE_KEYS
from passmd.protocols.fit.measurements import ANNOTATIONS, CONDITIONS, MEASURED, MODELS
from passmd.protocols.maps import MAP_QUANTITIES

EXAMPLES = int(os.environ.get("PASSMD_FUZZ_EXAMPLES", "250"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """One folder for the generated files (each example overwrites its file)."""
    return tmp_path_factory.mktemp("generated")


def _check_outcome(argv, status, out, err, caught, named: tuple[str, ...]):
    """Exit 0 (finite JSON if asked) or exit 2 with one line naming one of ``named``."""
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)], (argv, caught)
    assert "Traceback" not in err and "internal error" not in err, (argv, err)
    if status == 0:
        assert err == "", (argv, err)
        if "--json" in argv:
            _finite_json(out)
        return
    assert status == 2, (argv, status, err)
    assert out == "" and err.count("\n") == 1 and err.startswith("passmd"), (argv, err)
    assert any(name in err for name in named), (named, err)


# --------------------------------------------------------------------------------------
# Drive files: TOML documents with random keys, types, units, layout and encoding
# --------------------------------------------------------------------------------------

NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.floats(min_value=1e-6, max_value=1e6),
                    st.integers(min_value=-10**20, max_value=10**20))
WORDS = ["one", "paper-six", "flexible", "rigid", "steel", "0.5 mm", "5e6 N/m", "1.5e-5 kg", "0.4 N", "2 GPa",
         "202 nm", "40 V/us", "", "nan N", "1e400 m", "3 N", "-1 mm"]
SCALARS = st.one_of(
    NUMBERS, st.booleans(), st.sampled_from(WORDS), st.text(max_size=6),
    st.builds(lambda x, u: f"{x!r} {u}".strip(), NUMBERS, st.sampled_from(UNITS)),
    st.datetimes().map(lambda d: d.replace(microsecond=0)),
)
VALUES = st.one_of(
    SCALARS, st.lists(SCALARS, max_size=3),
    st.dictionaries(st.sampled_from(["count", "load_share", "normal_force", "radius", "mass", "x"]), SCALARS,
                    max_size=3),
    st.lists(st.dictionaries(st.sampled_from(["count", "load_share", "normal_force", "radius"]), SCALARS,
                             min_size=1, max_size=3), min_size=1, max_size=3),
)
#: Entries a user writes on purpose (so that many generated files pass every check).
PLAUSIBLE = [("preload", "0.5 N"), ("preload", 0.3), ("hemisphere_radius", "0.5 mm"), ("contacts", "one"),
             ("actuator.damping_ratio", 0.1), ("friction_coefficient", 0.25), ("runner_mass", "3 g"),
             ("actuator_model", "rigid"), ("load_cell", True), ("allow_extrapolation", False),
             ("actuator.stiffness", "5e6 N/m"), ("amplifier.slew_rate", "40 V/us"),
             ("hemisphere_material.name", "steel"), ("runner_material.youngs_modulus", "200 GPa")]
KEYS = [*DRIVE_KEYS, "drive.preload", "drive.actuator.mass", "actuator.mas", "Preload", "preload ", "x.y",
        "actuator", "amplifier", "hemisphere_material", "contact_groups.count", "ä"]


def _toml_key(key: str) -> str:
    parts = key.split(".")
    if all(part and all(c.isalnum() and c.isascii() or c in "_-" for c in part) for part in parts):
        return key
    return json.dumps(key)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, (int, str)):
        return str(value) if isinstance(value, int) else json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }"
    return value.isoformat()  # a datetime


@st.composite
def drive_files(draw) -> bytes:
    """The bytes of a drive file: dotted keys or [tables], sometimes a stray line or a key twice,
    saved as UTF-8 (with or without a byte-order mark, LF or CRLF) or, rarely, UTF-16."""
    entries = draw(st.lists(st.one_of(st.tuples(st.sampled_from(KEYS), VALUES), st.sampled_from(PLAUSIBLE)),
                            max_size=5))
    lines = []
    if draw(st.booleans()):  # [table] layout: the keys of a part under its header
        tables: dict[str, list[str]] = {}
        for key, value in entries:
            head, _, rest = key.rpartition(".")
            tables.setdefault(head, []).append(f"{_toml_key(rest or key)} = {_toml_value(value)}")
        lines = tables.pop("", [])
        for head, body in tables.items():
            lines += [f"[{_toml_key(head)}]", *body]
    else:
        lines = [f"{_toml_key(key)} = {_toml_value(value)}" for key, value in entries]
    if lines and draw(st.integers(0, 9)) == 0:
        lines.insert(draw(st.integers(0, len(lines))), draw(st.sampled_from(
            [lines[0], "preload = ", "[actuator", "= 1", draw(st.text(max_size=10))])))
    text = "\n".join(lines) + "\n"
    encoding = draw(st.sampled_from(["utf-8", "utf-8", "utf-8", "utf-8-sig", "crlf", "utf-16"]))
    if encoding == "crlf":
        return text.replace("\n", "\r\n").encode("utf-8", "surrogatepass")
    return text.encode(encoding, "surrogatepass")


@FUZZ
@given(data=drive_files(), command=st.sampled_from(["theory", "drive show"]), as_json=st.booleans())
# a quantity derived from a file's key (ζ from c_p) out of range: the line names the file
@example(data=b"actuator.viscosity = 8.0\n", command="theory", as_json=False)
def test_generated_drive_files_end_cleanly(folder, data, command, as_json):
    path = folder / "drive.toml"
    path.write_bytes(data)
    argv = [*command.split(), "--drive", str(path), *(["--json"] if as_json else [])]
    status, out, err, caught = run_main(argv)
    event(f"drive file: exit {status}")
    _check_outcome(argv, status, out, err, caught, (str(path),))


# --------------------------------------------------------------------------------------
# Measurement files: headers, separators, cells, line endings and encodings
# --------------------------------------------------------------------------------------

COLUMNS = [*CONDITIONS, *MEASURED, *(f"{m}_sd" for m in MEASURED), *MODELS, *ANNOTATIONS,
           "amplitude_m", "step_um", "Step_nm", "velocity_m_per_s", "temperature_K", "", " frequency_Hz "]
CELLS = st.one_of(
    NUMBERS.map(repr), st.integers(-5, 500).map(str), st.sampled_from(
        ["", "", "nan", "inf", "-0", "1,5", "1.5e3", "abc", "1", "6", "rigid", "flexible", " 100 ", "1e400"]),
    st.text(max_size=5),
)


@st.composite
def measurement_files(draw) -> bytes:
    header = draw(st.lists(st.sampled_from(COLUMNS), min_size=1, max_size=6))
    delimiter = draw(st.sampled_from([",", ",", ";", "\t", "|"]))
    rows = draw(st.lists(st.lists(CELLS, min_size=max(0, len(header) - 1), max_size=len(header) + 1),
                         max_size=6))
    if draw(st.integers(0, 4)) == 0:  # a well-formed table, so that some files pass every check
        header = ["amplitude_nm", "frequency_Hz", draw(st.sampled_from(list(MEASURED)))]
        rows = [[draw(st.sampled_from(["50", "100", "150.5"])), draw(st.sampled_from(["100", "1000", "1e3"])),
                 draw(st.sampled_from(["1", "64.25", "0.5", "-2"]))] for _ in range(draw(st.integers(1, 5)))]
    buffer = io.StringIO()
    writer = csv.writer(buffer, delimiter=delimiter, lineterminator=draw(st.sampled_from(["\n", "\r\n"])))
    writer.writerows([header, *rows])
    encoding = draw(st.sampled_from(["utf-8", "utf-8", "utf-8-sig", "utf-16", "latin-1"]))
    return buffer.getvalue().encode(encoding, "replace" if encoding == "latin-1" else "surrogatepass")


@FUZZ
@given(data=measurement_files())
def test_generated_measurement_files_end_cleanly(folder, data):
    from passmd.protocols import fit

    path = folder / "data.csv"
    path.write_bytes(data)
    argv = ["fit", str(path), "--free", "mu"]
    with mock.patch.object(fit, "fit", _reached):  # reaching the fit: every check passed
        try:
            status, out, err, caught = run_main(argv)
        except _Reached:
            event("measurement file: every check passed")
            return
    event(f"measurement file: exit {status}")
    _check_outcome(argv, status, out, err, caught, (str(path),))


# --------------------------------------------------------------------------------------
# --vary specifications
# --------------------------------------------------------------------------------------

QUANTITY_WITH_UNIT = st.builds(lambda x, u: f"{x!r}{u}", NUMBERS, st.sampled_from(UNITS))
VALUE_TEXT = st.one_of(QUANTITY_WITH_UNIT, st.sampled_from(
    ["100Hz", "1kHz", "0.4N", "60nm", "0.2", "1mm", "0", "-1", "nan", "", " ", "1e-300", "3e8kHz"]))
NAMES = st.sampled_from([*AXES, "foo", "", "Frequency", "mu ", "amplitude "])


#: Specifications a user writes on purpose (so that many generated ones pass every check).
PLAUSIBLE_SPECS = ["frequency=100Hz..1kHz:log:3", "amplitude=60nm..180nm:4", "preload=0.1N,0.4N,1N",
                   "mu=0.1..0.3:5", "radius=0.25mm,1mm", "frequency=2kHz", "amplitude=1e-7,2e-7",
                   "actuator-mass=1e-8..4e-8:2", "preload=0.2..0.6:log:3"]


@st.composite
def vary_specs(draw) -> str:
    form = draw(st.sampled_from(["range", "range", "list", "garbage", "plausible", "plausible", "plausible"]))
    if form == "plausible":
        return draw(st.sampled_from(PLAUSIBLE_SPECS))
    if form == "garbage":
        return draw(st.text(max_size=12))
    name = draw(NAMES)
    if form == "list":
        spec = ",".join(draw(st.lists(VALUE_TEXT, min_size=1, max_size=4)))
    else:
        spec = f"{draw(VALUE_TEXT)}..{draw(VALUE_TEXT)}"
        if draw(st.booleans()):
            spec += ":log"
        if draw(st.booleans()):
            count = st.one_of(st.integers(-2, 60).map(str), st.sampled_from(["1000", "1001", "x", ""]))
            spec += ":" + draw(count)
    return f"{name}={spec}" if draw(st.integers(0, 9)) else f"{name}{spec}"


@FUZZ
@given(quantity=st.sampled_from(list(MAP_QUANTITIES)),
       specs=st.one_of(*(st.lists(vary_specs(), min_size=n, max_size=n) for n in (1, 2))),
       as_json=st.booleans())
def test_generated_vary_specifications_end_cleanly(quantity, specs, as_json):
    from passmd.protocols import maps

    argv = ["sweep", quantity, *(a for spec in specs for a in ("--vary", spec))]
    argv += ["--json"] if as_json else []
    with mock.patch.object(maps, "compute_map", _reached):  # reaching the map: every check passed
        try:
            status, out, err, caught = run_main(argv)
        except _Reached:
            event(f"{quantity}: every check passed")
            return
    event(f"{quantity}: exit {status}")
    _check_outcome(argv, status, out, err, caught, ("--vary",))
    if status == 2 and len(specs) == 1 and not any(
            whole in err for whole in ("points is out of range", "expected one argument")):  # (argparse's)
        name = specs[0].partition("=")[0]
        assert any(typed in err for typed in (repr(specs[0]), f"--vary {name}", f"--vary at {name} = ")), \
            (specs, err)
