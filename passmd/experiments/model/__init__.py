"""The model chapter (Sections 2–3): figure data."""
