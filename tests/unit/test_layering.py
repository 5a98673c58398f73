"""The package's import structure (docs/architecture.md, "Layers"): no import circle between
modules, no private name imported from another module, and no module importing from a layer
above its own. Every import counts, also those inside functions. The gmsh builders of the
top-level meshes/ folder are the subpackage contactfx.meshes (pyproject.toml) and are scanned
with it."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2] / "contactfx"
#: installed as contactfx.meshes
MESHES = Path(__file__).parents[2] / "meshes"

#: layers from the top; a module may import from its own layer and the ones below
LAYERS = [
    {"cli", "__main__"},
    {"validation"},
    {"scenes"},
    {"driver"},
    {"numerics"},
    {"contact", "mechanics", "solvers", "io"},
    {
        "params",
        "results",
        "references",
        "_compat",
        "jit_cache",
        "contact_edge",
        "meshes",
        "__init__",
    },
]


def _modules() -> dict[str, Path]:
    out = {}
    for folder, package in ((ROOT, ("contactfx",)), (MESHES, ("contactfx", "meshes"))):
        for path in folder.rglob("*.py"):
            parts = package + path.relative_to(folder).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            out[name] = path
    return out


_PATHS: dict[str, Path] = {}


def _imports(path: Path, name: str) -> list[tuple[str, list[str]]]:
    """(imported contactfx module, names imported from it) for every import statement."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found += [(a.name, []) for a in node.names if a.name.startswith("contactfx")]
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([module] if module else []))
            if module.startswith("contactfx"):
                # "from package import module" imports the module, not the package
                subs = [a.name for a in node.names if f"{module}.{a.name}" in _PATHS]
                found += [(f"{module}.{n}", []) for n in subs]
                names = [a.name for a in node.names if a.name not in subs]
                if names:
                    found.append((module, names))
    return found


def _layer(module: str) -> int:
    parts = module.split(".")
    key = parts[1] if len(parts) > 1 else "__init__"
    for i, layer in enumerate(LAYERS):
        if key in layer:
            return i
    raise AssertionError(f"{module} is in no layer")


MODULES = _PATHS = _modules()
GRAPH = {
    name: {m for m, _ in _imports(path, name) if m in MODULES and m != name}
    for name, path in MODULES.items()
}


def test_no_import_circle():
    state: dict[str, int] = {}

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for n in sorted(GRAPH[m]):
            if state.get(n) == 1:
                pytest.fail("import circle: " + " -> ".join(stack[stack.index(n) :] + [n]))
            if n not in state:
                visit(n, stack + [n])
        state[m] = 2

    for m in sorted(MODULES):
        if m not in state:
            visit(m, [m])


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_private_import_and_no_upward_import(name):
    for module, names in _imports(MODULES[name], name):
        # _compat is a module of the package's own version layer, meant to be imported
        private = [n for n in names if n.startswith("_") and n != "_compat"]
        assert not private, f"{name} imports private {private} from {module}"
        assert _layer(module) >= _layer(name), f"{name} imports {module} from a higher layer"
