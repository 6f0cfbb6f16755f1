"""Game-engine layouts: which engine texture channel holds which region and wrinkle map, the
plan that assigns a project's areas to them within the engine's limits, and its export."""
