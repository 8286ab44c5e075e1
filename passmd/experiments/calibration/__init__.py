"""The calibration chapter (beyond the paper): fitting the unknowns of Sections 2–3 to measured steps."""
