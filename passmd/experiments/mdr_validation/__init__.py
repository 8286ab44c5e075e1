"""The MDR-validation chapter (Section 2, Eqs. 4–6): the contact model against the closed forms."""
