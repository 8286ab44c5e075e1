"""The drive's model: parameters (Tables 1–2), closed forms (Hertz, Cattaneo–Mindlin,
Eqs. 1, 7–14), the MDR contact with memory (Eqs. 4–6), driving waveforms and the Eq. 15
design, drive files and the protocol defaults."""
