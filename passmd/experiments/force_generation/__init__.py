"""The force-generation chapter, Section 4.2: the force generated against the load cell (Fig. 7)."""
