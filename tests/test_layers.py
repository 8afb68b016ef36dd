"""The package's imports point one way: md_inputs ← reduced_model ← analysis ← workflows.

Every import counts, at module level or inside a function, relative or absolute:
a lazy import is still a dependency.  No module imports a higher layer, and the
module graph has no cycle.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("md_inputs", "reduced_model", "analysis", "workflows")


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


def test_no_import_cycle():
    graph = _graph()
    state, stack, cycles = {}, [], []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for d in sorted(graph[m]):
            if m.startswith(d + "."):
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
    assert not cycles, "\n".join(cycles)
