"""The model chapter, Sections 2–3: the drive, its signal, Eq. 1's normal forces and the MDR contact."""
