"""What runs a computation, never what it computes: result cache, parallel sweeps, run
configuration, provenance, units at the edges, progress and input checks."""
