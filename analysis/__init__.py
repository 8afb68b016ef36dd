"""Analysis of stick-slip traces and confined-film trajectories."""
