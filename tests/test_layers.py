"""The package's imports point one way: md_inputs ← reduced_model ← analysis ← workflows.

Every import counts, at module level or inside a function, relative or absolute:
a lazy import is still a dependency.  No module imports a higher layer, and the
module graph has no cycle.  Inside a layer the sub-folders are floors too
(:data:`FLOORS`): a sub-folder imports no later one, and with each sub-folder taken
as one node (the layer's own modules each a node of their own) the graph still has
no cycle.  The command line (``workflows/cli/``) is imported by nothing outside it.  No
module imports another module's private (``_name``) names.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("md_inputs", "reduced_model", "analysis", "workflows")
#: the sub-folders of each layer, lowest first: a sub-folder imports no later one
FLOORS = {
    "reduced_model": ("laws", "integrators", "sfb"),
    "analysis": ("files", "ensemble", "energy", "structure", "slip_law", "observables", "calibration",
                 "groundtruth"),
    "workflows": ("md", "sweep", "report", "cost", "cli"),
}


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["filmfriction", *parts])


def _imports(path: Path) -> set[str]:
    """Project modules imported by the file at ``path`` (resolved to module names)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            found.add(mod)
            found.update(f"{mod}.{a.name}" for a in node.names)
    return {m for m in found if m == "filmfriction" or m.startswith("filmfriction.")}


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for layer in LAYERS for p in (ROOT / layer).rglob("*.py")}
    graph = {}
    for mod, path in files.items():
        # keep only names that are modules (``from .x import f`` also yields ``.x.f``)
        graph[mod] = {m for m in _imports(path) if m in files and m != mod}
    return graph


def _layer(module: str) -> int:
    return LAYERS.index(module.split(".")[1])


def test_no_import_points_up():
    upward = [f"{m} imports {d}" for m, deps in _graph().items() for d in deps
              if _layer(d) > _layer(m)]
    assert not upward, "\n".join(sorted(upward))


def test_no_top_level_names_but_filmfriction():
    # the fixed folders are sub-packages of filmfriction, never packages of their own
    for layer in LAYERS:
        with pytest.raises(ImportError):
            __import__(layer)


def _cycles(graph: dict[str, set[str]], *, own_package_ok: bool = False) -> list[str]:
    """The cycles of ``graph`` found by a depth-first walk, as "a -> b -> a" lines."""
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for d in sorted(graph.get(m, ())):
            if own_package_ok and m.startswith(d + "."):
                continue  # a module using its own package's public names
            if state.get(d) == 1:
                cycles.append(" -> ".join(stack[stack.index(d):] + [d]))
            elif d not in state:
                visit(d)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)
    return cycles


def test_no_import_cycle():
    cycles = _cycles(_graph(), own_package_ok=True)
    assert not cycles, "\n".join(cycles)

def _floor(module: str) -> str:
    """The node of ``module`` with each sub-folder of a layer taken as one:
    ``filmfriction.workflows.md.runner`` -> ``workflows.md``, a layer's own module
    (``filmfriction.workflows.study``) stays itself."""
    parts = module.split(".")[1:]
    if len(parts) >= 2 and parts[1] in FLOORS.get(parts[0], ()):
        return ".".join(parts[:2])
    return ".".join(parts)


def test_every_sub_folder_is_a_floor():
    # a new sub-folder is placed among the floors (or the rules below would skip it)
    for layer in LAYERS:
        subs = {p.parent.name for p in (ROOT / layer).glob("*/__init__.py")}
        assert subs == set(FLOORS.get(layer, ())), (layer, subs)


def test_no_sub_folder_imports_a_later_one():
    upward = []
    for m, deps in _graph().items():
        for d in deps:
            a, b = _floor(m).split("."), _floor(d).split(".")
            if (len(a) == 2 and len(b) == 2 and a[0] == b[0] and a[1] in FLOORS.get(a[0], ())
                    and b[1] in FLOORS[b[0]] and FLOORS[a[0]].index(b[1]) > FLOORS[a[0]].index(a[1])):
                upward.append(f"{m} imports {d}")
    assert not upward, "\n".join(sorted(upward))


def test_no_cycle_between_sub_folders():
    graph: dict[str, set[str]] = {}
    for m, deps in _graph().items():
        if m.endswith(".__init__") or any(m == f"filmfriction.{l}" for l in LAYERS):
            continue
        node = _floor(m)
        if node.count(".") == 1 and node.split(".")[1] in FLOORS.get(node.split(".")[0], ()) \
                and m == f"filmfriction.{node}":
            continue  # a sub-folder's __init__ gathers its own modules
        graph.setdefault(node, set()).update(
            _floor(d) for d in deps if _floor(d) != node and not node.startswith(_floor(d) + "."))
    cycles = _cycles(graph)
    assert not cycles, "\n".join(cycles)


def test_nothing_outside_the_command_line_imports_it():
    cli = "filmfriction.workflows.cli"
    users = [f"{m} imports {d}" for m, deps in _graph().items() for d in deps
             if (d == cli or d.startswith(cli + ".")) and not m.startswith(cli + ".")
             and m != cli]
    assert not users, "\n".join(sorted(users))


#: private names one module still takes from another, each with its reason (none else)
PRIVATE_IMPORTS_KEPT: set[tuple[str, str, str]] = set()


def test_no_private_name_is_imported_from_another_module():
    # a name with a leading underscore belongs to its module: a name another module
    # needs is public there (or lives where both can reach it)
    found = []
    for layer in LAYERS:
        for path in (ROOT / layer).rglob("*.py"):
            name = _module_name(path)
            package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if not isinstance(node, ast.ImportFrom):
                    continue
                if node.level:
                    base = package.split(".")[:len(package.split(".")) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                if source != "filmfriction" and not source.startswith("filmfriction."):
                    continue
                for alias in node.names:
                    private = alias.name.startswith("_") and not alias.name.startswith("__")
                    if private and source != name \
                            and (name, source, alias.name) not in PRIVATE_IMPORTS_KEPT:
                        found.append(f"{name} imports {alias.name} from {source}")
    assert not found, "\n".join(sorted(found))


def test_the_kept_private_imports_still_exist():
    # an entry of PRIVATE_IMPORTS_KEPT that no module needs any more is removed
    for module, source, private in PRIVATE_IMPORTS_KEPT:
        path = ROOT / Path(*module.split(".")[1:]).with_suffix(".py")
        text = path.read_text(encoding="utf-8")
        assert private in text and source.rsplit(".", 1)[1] in text, (module, private)


def test_every_module_has_a_base_name_of_its_own():
    # one name, one thing: the package's modules, the benchmarks and the tests
    # (a package's __init__, __main__ and the tests' conftest excepted)
    seen: dict[str, list[str]] = {}
    for folder in (*LAYERS, "benchmarks", "tests"):
        for path in (ROOT / folder).rglob("*.py"):
            if path.name not in ("__init__.py", "__main__.py", "conftest.py"):
                seen.setdefault(path.name, []).append(str(path.relative_to(ROOT)))
    shared = {name: paths for name, paths in seen.items() if len(paths) > 1}
    assert not shared, shared
