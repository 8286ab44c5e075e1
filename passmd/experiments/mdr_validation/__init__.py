"""The MDR-validation chapter: the contact model against the closed
forms (figure data and the comparisons behind it)."""
