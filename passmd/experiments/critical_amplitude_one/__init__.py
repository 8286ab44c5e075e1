"""The one-contact chapter, Section 4.1: the critical amplitude of one contact (Figs. 5a, 5b)."""
