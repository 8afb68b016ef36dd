"""The LAMMPS scripts ship with the package and are found by name."""
import re

import pytest

from filmfriction import md_inputs
from filmfriction.workflows.md import runner


def test_every_script_is_found_by_name():
    names = sorted(p.name for p in md_inputs.DIRECTORY.glob("*.lmp"))
    assert {"film_slide.lmp", "bulk_lj.lmp"} <= set(names)
    for name in names:
        path = md_inputs.script(name)
        assert path.is_absolute() and path.parent == md_inputs.DIRECTORY and path.name == name


def test_an_unknown_script_lists_the_known_ones():
    with pytest.raises(FileNotFoundError, match=r"no LAMMPS script 'film.lmp' .* have: "
                                                r"bulk_lj.lmp, film_slide.lmp"):
        md_inputs.script("film.lmp")


def test_the_film_script_writes_the_trace_columns_of_the_contract():
    # runner.TRACE_COLUMNS is what the analysis reads: the script's trace file names
    # each of them in its title, and prints one value per name
    text = md_inputs.script("film_slide.lmp").read_text()
    title = re.search(r'title "# ([^"]+)"', text)
    assert title, "no title line for the trace file"
    names = title.group(1).split()
    assert sorted(names) == sorted(runner.TRACE_COLUMNS)
    printed = re.search(r'^ "(\$\(.*\))" &$', text, re.M)
    assert printed and len(re.findall(r"\$\(", printed.group(1))) == len(names)
