"""Each layer imports only the layers below it (docs/architecture.md), read from the source.

Top-level and function-level imports both count: a lazy import of a higher layer is still a
dependency on it.
"""

import ast
import re
from pathlib import Path

import recipdyn

SRC = Path(recipdyn.__file__).parent

#: Layers from the floor up; a module may import its own layer and any lower one.
LAYERS = [
    {"errors", "defaults", "io", "locking", "resources", "parallel", "progress", "mplstyle",
     "quantity"},
    {"model"},
    {"units", "config"},  # read the model's parameter schema
    {"integrate"},
    {"analysis"},
    {"simulate", "io_signal", "sensors", "chain"},  # sensors read records; chain describes them
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
#: An import string ``recipdyn.model.X:OBJ`` (a routing table: the registry's, family's).
_IMPORT_STRING = re.compile(r"recipdyn\.model\.([\w.]+):\w+")


def _node(rel: tuple[str, ...]) -> str:
    """The dotted name of a module inside the model package (a package by its own name)."""
    return ".".join(rel[:-1] if rel[-1] == "__init__" else rel)


def _strings(tree: ast.AST) -> list[str]:
    return [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
            and isinstance(n.value, str)]  # fmt: skip


def _model_graph(root: Path = MODEL, package: str = "recipdyn.model") -> dict[str, set[str]]:
    """Module -> modules of the model package (or of ``package`` at ``root``) it imports:
    relative and absolute imports (lazy ones included) and the imports written in the text of
    generated glue (a string ``from recipdyn.model.X import ...``, run when the glue is
    loaded). Import strings ``recipdyn.model.X:OBJ`` are routing tables, not edges
    (`_routes`)."""
    prefix, depth = f"{package}.", len(package.split("."))
    glue = re.compile(rf"(?:from|import)\s+{re.escape(package)}\.([\w.]+)")
    graph: dict[str, set[str]] = {}
    paths = {p: p.relative_to(root).with_suffix("").parts for p in root.rglob("*.py")}
    names = {_node(rel) for rel in paths.values()} - {""}

    def known(dotted: list[str]) -> set[str]:
        """The longest prefix of ``dotted`` that is a module here (a package's own module is
        not a dependency of what it holds)."""
        hits = [".".join(dotted[:k]) for k in range(len(dotted), 0, -1)]
        return {next((h for h in hits if h in names), "")} - {""}

    for path, rel in paths.items():
        package = list(rel[:-1])
        tree = ast.parse(path.read_text(encoding="utf-8"))
        deps = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level:
                if node.level - 1 > len(package):
                    continue  # above the model package
                mod = package[: len(package) - node.level + 1]
                mod += node.module.split(".") if node.module else []
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith(prefix):
                mod = node.module.split(".")[depth:]
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith(prefix):
                        deps |= known(a.name.split(".")[depth:])
                continue
            else:
                continue
            for a in node.names:
                deps |= known([*mod, a.name])
        for text in _strings(tree):
            for m in glue.findall(text):
                deps |= known(m.split("."))
        graph[_node(rel)] = deps - {_node(rel)}
    return graph


def _routes(path: Path) -> set[str]:
    """The modules of the model package that ``path`` names in import strings."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {m for text in _strings(tree) for m in _IMPORT_STRING.findall(text)
            if _IMPORT_STRING.fullmatch(text)}  # fmt: skip


def _model_modules() -> set[str]:
    """The modules that are models (a registered `Model` each): the ones the registry's
    built-in table names, and the one assembler's machines of one throw that ``compressor``
    delegates to (``family.ASSEMBLER``)."""
    from recipdyn.model import family, registry

    tables = [*registry._BUILTIN.values(), registry.MACHINE_MODEL, family.ASSEMBLER]
    return {t.partition(":")[0].removeprefix("recipdyn.model.") for t in tables}


def _model_edges(graph: dict[str, set[str]], models: set[str]) -> set[tuple[str, str]]:
    """``(a, b)``: model module ``a`` imports model module ``b``, directly or through parts
    (modules that are no model: a part that imports a model would join two models)."""
    edges = set()
    for a in sorted(models & set(graph)):
        seen, todo = {a}, list(graph[a])
        while todo:
            m = todo.pop()
            if m in seen:
                continue
            seen.add(m)
            if m in models:
                edges.add((a, m))
            else:
                todo.extend(graph.get(m, ()))
    return edges


#: The model modules of the compressor (the registry's and family's tables must name them).
MODEL_MODULES = {"family", "assembler.model", "reference.compressor_guide"}


def test_no_model_module_imports_another():
    """No model module imports another model's module, directly, lazily, through a part
    (a shared module that is no model) or in the text of the glue a part generates: every
    model is assembled from shared parts (`model/components/`, `model/joints/`, ...).

    ``family`` (the model ``compressor``) is a model module like the others: its imports are
    checked the same way (it imports none). It reaches the machines of one throw only
    through ``family.ASSEMBLER`` (an import string ``recipdyn.model.X:OBJ``, imported
    when a configuration first asks for one): `test_only_the_routing_tables_name_models`
    checks that those strings are the table's and nothing else's, and since family is a
    model module, an implementation that imported it back would fail here."""
    models = _model_modules()
    assert MODEL_MODULES <= models, sorted(MODEL_MODULES - models)
    assert {"reference", "reference.double_pendulum"} <= models  # the reference models too
    edges = _model_edges(_model_graph(), models)
    assert not edges, sorted(edges)


def test_only_the_routing_tables_name_models():
    """Import strings of models appear in the two routing tables only: the registry's
    (model name -> model, and machine file -> the machines' model) and family's
    ``ASSEMBLER`` (route -> machine of one throw), each naming exactly its table's modules;
    no other module
    of the model package holds one."""
    from recipdyn.model import family, registry

    found = {_node(p.relative_to(MODEL).with_suffix("").parts): _routes(p)
             for p in MODEL.rglob("*.py")}  # fmt: skip
    tables = {"registry": {**registry._BUILTIN, "machine files": registry.MACHINE_MODEL},
              "family": {"assembler": family.ASSEMBLER}}  # fmt: skip
    for name, table in tables.items():
        want = {t.partition(":")[0].removeprefix("recipdyn.model.") for t in table.values()}
        assert found.pop(name) == want, name
    assert not {k: v for k, v in found.items() if v}


def test_the_model_checker_sees_an_edge(tmp_path):
    """The model-import checker can fail: a direct relative import, an absolute lazy one, an
    import through a part and one in the text of a part's generated glue are each found,
    and a part shared by two models is not an edge."""
    root = tmp_path / "model"
    (root / "parts").mkdir(parents=True)
    files = {
        "__init__.py": "",
        "a.py": "from .parts.shared import f\n",
        "b.py": "from .parts import shared\n",
        "c.py": "from . import b\n",
        "d.py": "def f():\n    from recipdyn.model.c import x\n",
        "e.py": "from .parts.glue import g\n",
        "parts/__init__.py": "",
        "parts/shared.py": "import math\n",
        "parts/glue.py": 'SRC = """\nfrom recipdyn.model.a import f\n"""\n',
    }
    for name, text in files.items():
        (root / name).write_text(text)
    graph = _model_graph(root)
    assert _model_edges(graph, {"a", "b", "c", "d", "e"}) == {("c", "b"), ("d", "c"),
                                                               ("e", "a")}  # fmt: skip


def _first_cycle(graph: dict[str, set[str]]) -> str | None:
    """A cycle of ``graph`` as ``a -> b -> a`` (depth-first), None if there is none."""
    state: dict[str, int] = {}

    def visit(node, path):
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return " -> ".join([*path, node, nxt])
            if nxt not in state and (found := visit(nxt, [*path, node])):
                return found
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node, [])):
            return found
    return None


def test_the_cycle_finder_finds_a_lazy_cycle_and_passes_a_package_import(tmp_path):
    """A lazy import closes a cycle; ``from . import sub`` inside a package's module is an
    edge to the submodule, not to the package that holds it."""
    root = tmp_path / "pkg"
    (root / "sub").mkdir(parents=True)
    files = {"__init__.py": "from .a import f\n", "a.py": "from .sub import k\n",
             "sub/__init__.py": "", "sub/k.py": "def g():\n    from recipdyn.b import h\n",
             "b.py": "import math\n"}  # fmt: skip
    for name, text in files.items():
        (root / name).write_text(text)
    assert _first_cycle(_model_graph(root, "recipdyn")) is None
    (root / "b.py").write_text("def h():\n    from .a import f\n")
    assert _first_cycle(_model_graph(root, "recipdyn")).endswith("a -> sub.k -> b -> a")


def test_no_import_cycles_anywhere():
    """Lazy imports count, across the whole package (issue 43: ``features <-> sweep.run <->
    sweep.work`` and the diagnosis modules' ``diagnose <-> train <-> machine`` were cycles;
    the cli's commands imported their package)."""
    graph = _model_graph(SRC, "recipdyn")
    assert len(graph) > 100 and "diagnosis.train" in graph
    assert (cycle := _first_cycle(graph)) is None, cycle


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
