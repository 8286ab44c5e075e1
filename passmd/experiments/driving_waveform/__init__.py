"""Section 5, driving waveform (Figs. 8–10): figure data, claim
extractors, the facts the chapter quotes and studies beyond the paper."""
