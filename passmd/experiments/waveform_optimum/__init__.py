"""Beyond the paper: the settling time, a numerical optimum of Eq. 15's waveform, flexible actuators."""
