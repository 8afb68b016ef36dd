"""LAMMPS's output of one run: read (lammps_output, trace_dat) and checked (sanity)."""
