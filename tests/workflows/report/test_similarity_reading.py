"""The similarity section's reading of the Bingham number: what it says at Bi ~ 1 and at Bi >> 1."""
from types import SimpleNamespace

from filmfriction.workflows.report.sfb_sections import similarity_section


def _text(bi, lo, hi, tmp_path):
    row = {"name": "bingham_number", "klein": 1.1e4, "model": bi, "ratio": bi / 1.1e4,
           "uncertainty": [lo, hi], "note": "eta_eff/eta_bulk", "source": "similarity"}
    sec = similarity_section(SimpleNamespace(rows=[row]), [tmp_path], {})
    return " ".join(b for b in sec.blocks if isinstance(b, str))


def test_a_film_near_bulk_points_to_the_ladder_and_claims_nothing_of_klein(tmp_path):
    text = _text(1.4, 1.3, 1.5, tmp_path)
    assert "cannot by itself show a viscous film" in text, text
    assert "filmfriction ladder plan" in text and "mass-ladder.md" in text, text


def test_a_film_at_a_large_bingham_number_states_the_measured_answer_and_its_limits(tmp_path):
    text = _text(50.0, 40.0, 60.0, tmp_path)
    assert "Bi ≫ 1 here, though far below Klein's" in text, text
    assert "near Klein's" in _text(1.2e4, 1.0e4, 1.4e4, tmp_path)
    # one run cannot decide; the runs pooled can, and the text says what they give
    assert "not established by a run" in text and "no power to resolve" in text, text
    assert "pooled" in text and "`filmfriction slip-law`" in text and "`mixed`" in text, text
    assert "filmfriction ladder plan" not in text, text
