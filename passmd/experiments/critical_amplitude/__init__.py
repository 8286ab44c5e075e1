"""Section 4.1, critical amplitude (Figs. 5 and 6): figure data,
claim extractors and the facts the chapters quote."""
