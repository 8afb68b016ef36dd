"""The files the analysis reads and writes: traces (a run directory, a plain or
analysed trace file, a LAMMPS log) and how a file's columns are read, the per-slip
CSV, the documents read back with their checks, the provenance every document
carries, and the helpers they share (atomic writes, JSON-safe numbers, numbers as
text, figures as PNG bytes).

* :mod:`~filmfriction.analysis.files.trace` — a trace: its columns, parameters and units;
* :mod:`~filmfriction.analysis.files.trace_reader` — a trace read from a run directory, a
  plain file or an analysed one, through
  :mod:`~filmfriction.analysis.files.trace_table` (a text table's header and rows) and
  :mod:`~filmfriction.analysis.files.trace_cache` (the binary copy of a large one);
* :mod:`~filmfriction.analysis.files.column_spec` — ``--column``/``--skip-rows`` as the
  user says them;
* :mod:`~filmfriction.analysis.files.lammps_log` — a LAMMPS log's thermo output as a trace;
* :mod:`~filmfriction.analysis.files.cycles_csv` — ``analysis_cycles.csv``;
* :mod:`~filmfriction.analysis.files.documents` — the documents read back, checked;
* :mod:`~filmfriction.analysis.files.provenance` — what made a document, from what;
* :mod:`~filmfriction.analysis.files.util` — atomic writes and the small shared helpers.
"""
