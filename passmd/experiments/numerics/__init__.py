"""The numerics chapter: trust in the integrator (convergence, energy, cost)."""
