"""The driving-waveform chapter, Section 5.1: Eq. 15's waveform against the saw-tooth (Figs. 8, 9a)."""
