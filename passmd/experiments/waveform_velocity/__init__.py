"""Velocity against driving frequency, Section 5.2: the saw-tooth and Eq. 15's waveform (Figs. 9b, 10)."""
