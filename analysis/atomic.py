"""Kept for ``workflows/calibrate.py`` only, until it moves: write_atomic lives in
:mod:`filmfriction.analysis.util`.  Import it from there."""
from .util import write_atomic

__all__ = ["write_atomic"]
