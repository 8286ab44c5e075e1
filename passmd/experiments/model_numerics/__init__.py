"""The numerics chapter (beside Sections 2–3): trust in the integrator (convergence, energy, cost)."""
