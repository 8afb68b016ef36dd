"""The shipped scenes (``*.toml``, read by :mod:`filmfriction.workflows.md.scene`) and the
parameter table they are checked against (:mod:`.parameters`)."""
