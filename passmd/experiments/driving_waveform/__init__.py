"""The driving-waveform chapter, Section 5: Eq. 15's optimized waveform against the saw-tooth (Figs. 8–10)."""
