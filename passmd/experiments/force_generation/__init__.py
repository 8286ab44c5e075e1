"""Section 4.2, force generation (Fig. 7): figure data, claim
extractors and the facts the chapter quotes."""
