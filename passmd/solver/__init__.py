"""The hybrid simulation of runner, actuators and MDR contacts (Eqs. 2–3): the simulation
object, its integration schemes and time steps, and the numba kernels."""
