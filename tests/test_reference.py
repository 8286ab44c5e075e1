"""Closed-form reference curves in passmd/data/reference/: regenerated, hand-checked, discriminating.

Tolerances:
* committed files vs a fresh computation: the files hold 10 significant digits
  (``CSV_FLOAT_FORMAT``), so rtol = 1e-8 allows only last-digit rounding;
* hand arithmetic: hand values are written with 6 significant digits, rtol = 1e-5.
"""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from passmd.ledger import reference
from passmd.model.tables import PRELOAD_GRIDS

WRITTEN = 1e-8  # 10 significant digits in the CSV files
HAND = 1e-5  # 6 significant digits typed from the hand calculation
CLAIMS = Path(reference.REFERENCE_DIR) / "claims.csv"


def _row(name, preload):
    table = reference.load_reference_curve(name)
    row = table[np.isclose(table["preload_N"], preload, rtol=0, atol=1e-12)]
    assert len(row) == 1
    return row.iloc[0]


@pytest.mark.parametrize("name", sorted(reference.CURVES))
def test_committed_curves_equal_a_fresh_computation(name):
    committed = reference.load_reference_curve(name)
    fresh = reference.closed_form_curves(name)
    assert list(committed.columns) == list(fresh.columns)
    np.testing.assert_allclose(committed.to_numpy(float), fresh.to_numpy(float), rtol=WRITTEN, atol=0)
    spec = reference.CURVES[name]
    grid = PRELOAD_GRIDS[spec.hemisphere_radius]
    np.testing.assert_allclose(committed["preload_N"], grid, rtol=0, atol=1e-12)
    text = (reference.REFERENCE_DIR / spec.filename).read_text(encoding="utf-8")
    header = "".join(line for line in text.splitlines(True) if line.startswith("#"))
    assert header == reference.curve_header(name)  # parameters named in the header are current


def test_fig5b_row_by_hand():
    """One contact, R = 1 mm, F_p = 0.4 N, μ = 0.2.

    Eq. 7: u_x,max = 39.5074 nm (hand calculation in tests/test_theory.py::test_presliding_eq7_by_hand).
    Eq. 9: u_x,a = 0.2·0.4/6.5e6 · (3e-3 + 2.2e-8)/3e-3 = 1.230769e-8 · 1.0000073 = 12.3078 nm.
    Eq. 8: A_c = 39.5074 + 12.3078 = 51.8152 nm.
    """
    row = _row("fig5b_closed_form", 0.4)
    assert row["u_x_max_nm"] == pytest.approx(39.5074, rel=HAND)
    assert row["u_x_a_nm"] == pytest.approx(12.3078, rel=HAND)
    assert row["u_x_max_plus_u_x_a_nm"] == pytest.approx(51.8152, rel=HAND)


def test_fig6a_row_by_hand():
    """Six contacts, rigid, R = 1 mm, F_p = 0.4 N, μ = 0.2.

    Eq. 1: F_N1 = F_p/√2, F_N2 = F_p/(2√2). Eq. 10 scales as F^(2/3), so
    u_x,max,1 = 39.5074 · 2^(−1/3) = 39.5074 · 0.793701 = 31.3570 nm and
    u_x,max,2 = 39.5074 · 2^(−1) = 19.7537 nm.
    Eq. 11: u_x,max,e = 2·31.3570·19.7537/(31.3570 + 19.7537) = 1238.84/51.1107 = 24.2383 nm.
    """
    row = _row("fig6a_closed_form", 0.4)
    assert row["u_x_max_1_nm"] == pytest.approx(31.3570, rel=HAND)
    assert row["u_x_max_2_nm"] == pytest.approx(19.7537, rel=HAND)
    assert row["u_x_max_e_nm"] == pytest.approx(24.2383, rel=HAND)


def test_fig6c_row_by_hand():
    """Six contacts, flexible, R = 0.25 mm, F_p = 0.2 N, μ = 0.2.

    Eq. 10 scales as F^(2/3)/R^(1/3): (0.2/0.4)^(2/3)·(1/0.25)^(1/3) = 1, so the presliding
    equals the R = 1 mm, 0.4 N values: u_x,max,1 = 31.3570 nm, u_x,max,2 = 19.7537 nm.
    Eq. 14 (k_p = 4e6 N/m, m_a = 1.1e-8 kg): F_N1 = 0.2/√2 = 0.141421 N,
    u_x,a,1 = 0.2·0.141421/4e6 · (3e-3 + 1.1e-8)/3e-3 = 7.07107e-9 · 1.0000037 = 7.07109 nm,
    u_x,a,2 = 3.53555 nm. Eq. 13: u*1 = 38.4281 nm, u*2 = 23.2892 nm.
    Eq. 12: u*_x,max,e = 2·38.4281·23.2892/61.7173 = 29.0019 nm.
    """
    row = _row("fig6c_closed_form", 0.2)
    assert row["u_x_a_1_nm"] == pytest.approx(7.07109, rel=HAND)
    assert row["u_x_a_2_nm"] == pytest.approx(3.53555, rel=HAND)
    assert row["u_x_max_1_star_nm"] == pytest.approx(38.4281, rel=HAND)
    assert row["u_x_max_2_star_nm"] == pytest.approx(23.2892, rel=HAND)
    assert row["u_x_max_e_star_nm"] == pytest.approx(29.0019, rel=HAND)


def _claims():
    return pd.read_csv(CLAIMS, dtype=str, keep_default_na=False).set_index("id")


def _separating(reference_curve, other_curve):
    """Largest relative band t that keeps [r(1−t), r(1+t)] and [o(1−t), o(1+t)] apart everywhere."""
    r, o = np.asarray(reference_curve), np.asarray(other_curve)
    return float(np.min(np.abs(r - o) / (r + o)))


@pytest.mark.parametrize(
    ("claim", "competitors"),
    [
        ("fig5b-rigid-ac-matches-eq7", ["u_x_max_plus_u_x_a_nm"]),
        ("fig5b-flexible-ac-matches-eq8", ["u_x_max_nm"]),
        ("fig6a-rigid-ac-matches-eq11", ["u_x_max_1_nm", "u_x_max_2_nm"]),
        ("fig6b-flexible-r1-ac-matches-eq12", ["u_x_max_1_star_nm", "u_x_max_2_star_nm"]),
        ("fig6c-flexible-r025-ac-matches-eq12", ["u_x_max_1_star_nm", "u_x_max_2_star_nm"]),
    ],
)
def test_curve_claim_tolerance_tells_the_closed_forms_apart(claim, competitors):
    """The tolerance reasons in claims.csv say the band separates the claimed closed form from
    the competing curves of the same figure (Eq. 7 vs Eq. 8; Eq. 11/12 vs Eq. 10/13)."""
    row = _claims().loc[claim]
    assert row["tolerance_kind"] == "rel"
    filename, column = row["reference"].split(":")
    table = reference.load_reference_curve(filename)
    for other in competitors:
        assert float(row["tolerance"]) < _separating(table[column], table[other]), other


def test_write_reference_curves_round_trip(tmp_path):
    written = reference.write_reference_curves(tmp_path)
    assert sorted(p.name for p in written) == sorted(spec.filename for spec in reference.CURVES.values())
    assert not list(tmp_path.glob(".*.tmp"))  # no temporary file left behind
    again = reference.load_reference_curve("fig6b_closed_form.csv", directory=tmp_path)
    pd.testing.assert_frame_equal(again, reference.load_reference_curve("fig6b_closed_form"))


def test_unknown_curve_and_missing_file_are_clear_errors(tmp_path):
    with pytest.raises(ValueError, match="name = 'fig5a_closed_form' is not allowed"):
        reference.closed_form_curves("fig5a_closed_form")
    with pytest.raises(FileNotFoundError, match="make_reference_curves.py"):
        reference.load_reference_curve("fig5b_closed_form", directory=tmp_path)


def test_reference_curves_scale_with_mu():
    """Eqs. 7–14 are proportional to μ (the assumption's stated sensitivity)."""
    base = reference.closed_form_curves("fig6b_closed_form")
    raised = reference.closed_form_curves("fig6b_closed_form", friction_coefficient=0.3)
    cols = [c for c in base.columns if c.endswith("_nm")]
    np.testing.assert_allclose(raised[cols].to_numpy(), 1.5 * base[cols].to_numpy(), rtol=1e-12)
    assert "friction_coefficient_sections_4_1_and_5" in {a.key for a in reference.ASSUMPTIONS}


def test_tangential_stiffness_grows_with_radius():
    """2aG* ∝ a ∝ R^(1/3) at a given normal force: R = 1 mm is 4^(1/3) = 1.5874 times stiffer."""
    table = reference.tangential_stiffness_table()
    wide = table.pivot_table(index=["preload_N", "side"], columns="radius_mm",
                             values="tangential_stiffness_N_per_m")
    np.testing.assert_allclose(wide[1.0] / wide[0.25], 4 ** (1 / 3), rtol=1e-12)


def test_writing_needs_a_folder_and_the_data_is_package_data():
    # The package never writes into its installation: no default target folder.
    with pytest.raises(ValueError, match="directory = None"):
        reference.write_reference_curves(None)
    # The committed tables are read through importlib.resources, from inside the package.
    from importlib import resources

    packaged = resources.files("passmd") / "data" / "reference"
    assert Path(str(packaged)) == reference.REFERENCE_DIR
    assert {spec.filename for spec in reference.CURVES.values()} | {"claims.csv"} <= {
        entry.name for entry in packaged.iterdir()}
