"""Each layer imports only the layers below it (docs/architecture.md), read from the source.

Top-level and function-level imports both count: a lazy import of a higher layer is still a
dependency on it.
"""

import ast
from pathlib import Path

import recipdyn

SRC = Path(recipdyn.__file__).parent

#: Layers from the floor up; a module may import its own layer and any lower one.
LAYERS = [
    {"errors", "defaults", "io", "locking", "resources", "parallel", "progress", "mplstyle"},
    {"model"},
    {"units", "config"},  # read the model's parameter schema
    {"integrate"},
    {"analysis"},
    {"simulate", "io_signal", "sensors"},  # sensors read records
    {"plotting", "analyze", "compare", "animate"},
    {"sweep", "features"},  # features reads sweep stores
    {"diagnosis"},  # data sets, diagnosers: simulate + sensors + features, sweep's backends
    {"reproduce", "app"},
    {"cli", "__main__"},
]  # fmt: skip
RANK = {name: i for i, names in enumerate(LAYERS) for name in names}


def _imports(path: Path, package: list[str]) -> set[str]:
    """Top-level recipdyn subpackages/modules that ``path`` imports."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                parts = base + (node.module.split(".") if node.module else [])
                names = [parts[1]] if len(parts) > 1 else [a.name for a in node.names]
            elif node.module and node.module.split(".")[0] == "recipdyn":
                parts = node.module.split(".")
                names = [parts[1]] if len(parts) > 1 else [a.name for a in node.names]
            else:
                continue
            found.update(names)
        elif isinstance(node, ast.Import):
            for a in node.names:
                parts = a.name.split(".")
                if parts[0] == "recipdyn" and len(parts) > 1:
                    found.add(parts[1])
    return found


def test_every_module_has_a_layer():
    modules = {p.stem for p in SRC.glob("*.py") if p.stem != "__init__"}
    tops = modules | {p.parent.name for p in SRC.glob("*/__init__.py")}
    assert tops <= set(RANK), sorted(tops - set(RANK))


def test_no_layer_imports_a_higher_one():
    bad = []
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC).with_suffix("")
        package = ["recipdyn", *rel.parts[:-1]]  # the package a relative import starts from
        own = rel.parts[0]
        if own == "__init__":
            continue  # the package root re-exports the public API
        for name in _imports(path, package):
            if name in RANK and RANK[name] > RANK[own]:
                bad.append(f"{rel}: imports {name} (layer {RANK[name]} > {RANK[own]})")
    assert not bad, "\n".join(sorted(bad))


def test_the_checker_sees_a_violation(tmp_path):
    """The reader finds relative, absolute and function-level imports (it can fail)."""
    f = tmp_path / "m.py"
    f.write_text("def f():\n    from ..sweep.run import x\n    import recipdyn.cli\n"
                 "from . import spectrum\n")  # fmt: skip
    assert _imports(f, ["recipdyn", "analysis"]) == {"sweep", "cli", "analysis"}


# Inside the model layer: models are assembled from shared parts, never from each other.
MODEL = SRC / "model"
#: Modules that are models (a Model subclass each) rather than parts of one.
MODEL_MODULES = {"compressor", "compressor_contact", "compressor_valves",
                 "compressor_contact_valves"}  # fmt: skip
#: Imports between models that remain until the dynamic valves and the contact joint are
#: components of the assembled compressor (docs/components.md); the list may only shrink.
LEGACY_MODEL_EDGES = {("compressor_valves", "compressor"),
                      ("compressor_contact_valves", "compressor_contact")}  # fmt: skip


def _model_graph() -> dict[str, set[str]]:
    """Module -> model modules it imports (dotted names inside recipdyn.model, lazy imports
    included)."""
    graph: dict[str, set[str]] = {}
    names = {".".join(p.relative_to(MODEL).with_suffix("").parts) for p in MODEL.rglob("*.py")}
    for path in MODEL.rglob("*.py"):
        rel = path.relative_to(MODEL).with_suffix("").parts
        me = ".".join(rel)
        package = list(rel[:-1])
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.ImportFrom) and node.level):
                continue
            if node.level - 1 > len(package):
                continue  # above the model package
            base = package[: len(package) - node.level + 1]
            mod = base + (node.module.split(".") if node.module else [])
            for cand in [".".join(mod)] + [".".join([*mod, a.name]) for a in node.names]:
                if cand in names:
                    deps.add(cand)
        graph[me] = deps - {me}
    return graph


def test_no_model_module_imports_another():
    graph = _model_graph()
    edges = {(a, b) for a, deps in graph.items() for b in deps
             if a in MODEL_MODULES and b in MODEL_MODULES}  # fmt: skip
    assert edges <= LEGACY_MODEL_EDGES, sorted(edges - LEGACY_MODEL_EDGES)


def test_no_import_cycles_inside_the_model_layer():
    """Lazy imports count: a cycle (cycle <-> load <-> realgas before) means no module of it
    can be understood or tested alone."""
    graph = _model_graph()
    state: dict[str, int] = {}

    def visit(node, path):
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                raise AssertionError(" -> ".join([*path, node, nxt]))
            if nxt not in state:
                visit(nxt, [*path, node])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])
    assert len(graph) > 20  # the reader found the model's modules
