"""One MD run: scenes, fidelity presets, the LAMMPS engine and build, the runner,
its restarts and its lock."""
