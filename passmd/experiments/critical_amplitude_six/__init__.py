"""The six-contact chapter, Section 4.1: the critical amplitude of six contacts (Figs. 6a–c)."""
