"""The package's layout: layers that import only the layers above them, no import loop (not even
one hidden in a function), and no module that does several jobs (over 700 lines)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "nctwin"

#: The layers, top first: a module imports only modules of its own layer or the ones above it.
LAYERS = (
    ("_rows", "paths", "checks", "runner", "_geometry_loops", "metrics"),
    ("toolpath", "cache"),
    ("motion", "geometry", "controls", "machine", "limits"),
    ("gcode", "naivecam", "targets"),
    ("report",),
    ("physics",),
    ("kernel",),
    ("programs",),
    ("recordings", "mtconnect", "runtimes"),
    ("learn",),
    ("methods",),
    ("estimate",),
    ("identify", "record", "calibrate"),
    ("chapters",),
    ("cli",),
)
MAX_LINES = 700


def _modules() -> dict[str, Path]:
    out = {}
    for p in sorted(SRC.rglob("*.py")):
        parts = p.relative_to(SRC).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if parts:  # the package's own __init__ only re-exports the readers
            out[".".join(parts)] = p
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """Modules of the package that ``name`` imports anywhere in its file (functions too)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".") if package else []
                base = base[: len(base) - (node.level - 1)] if node.level > 1 else base
                target = ".".join([*base, *([node.module] if node.module else [])])
            elif (node.module or "").startswith("nctwin"):
                target = node.module.removeprefix("nctwin").lstrip(".")
            else:
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}" if target else alias.name
                found.add(sub if sub in modules else target)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("nctwin."):
                    found.add(alias.name.removeprefix("nctwin."))
    # importing a.b runs the package a's __init__ first
    found |= {m.rpartition(".")[0] for m in found if "." in m}
    return {m for m in found if m in modules and m != name and not name.startswith(f"{m}.")}


def _layer(name: str) -> int:
    for i, names in enumerate(LAYERS):
        if name.split(".")[0] in names:
            return i
    raise AssertionError(f"module nctwin.{name} is in no layer of LAYERS")


MODULES = _modules()
GRAPH = {name: _imports(name, path, MODULES) for name, path in MODULES.items()}


@pytest.mark.parametrize("name", sorted(MODULES))
def test_a_module_imports_only_its_layer_and_the_ones_above(name):
    below = sorted(m for m in GRAPH[name] if _layer(m) > _layer(name))
    assert not below, f"nctwin.{name} imports from lower layers: {below}"


def test_no_import_loop():
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(GRAPH[node]):
            if state.get(nxt) == 1:
                loop = [*stack[stack.index(nxt) :], nxt]
                raise AssertionError(f"import loop: {' -> '.join(loop)}")
            if nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = 2

    for name in sorted(GRAPH):
        if name not in state:
            visit(name, [name])


def test_methods_do_not_import_chapters():
    for name in MODULES:
        if name.startswith("methods."):
            assert not {m for m in GRAPH[name] if m.startswith("chapters")}, name


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_module_does_several_jobs(name):
    n = len(MODULES[name].read_text().splitlines())
    assert n <= MAX_LINES, f"nctwin.{name} has {n} lines (at most {MAX_LINES})"


#: The layers that may read reproduced results: the chapters write them, the report renders them.
READS_RESULTS = ("chapters", "report")


@pytest.mark.parametrize("name", sorted(MODULES))
def test_only_chapters_and_the_report_read_results(name):
    """A kernel, an estimator or the command line never looks anything up in results/: what is
    fitted lives in the machine's profile file."""
    if name.split(".")[0] in READS_RESULTS or name == "paths":
        return
    text = MODULES[name].read_text()
    for needle in ("results_dir", '"results"', "'results'", "results/"):
        assert needle not in text, f"nctwin.{name} reads results ({needle!r})"
