"""The calibration chapter: data made by other means than the fit's forward model, and the fits that
show what a calibration can and cannot tell (a comb of minima, a wrong fly-back rule)."""
