"""Scenes, the LAMMPS runner, sweeps and comparison reports."""
