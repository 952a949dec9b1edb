"""The shape of the library, read from its source with Python's ast (nothing is imported):

* no import circle among lipjax's modules, counting imports inside functions (they hide a circle, they do not
  remove it);
* no function longer than `MAX_FUNCTION_LINES`;
* a thin command line: lipjax/cli.py at most `MAX_CLI_LINES` lines, each `_cmd_*` at most `MAX_COMMAND_LINES`
  (it passes its arguments to one library function, where the logic lives and is tested);
* the library never imports `experiments`, `benchmarks` or `research` (they depend on the library, not the other
  way round);
* benchmarks/ and research/ are packages run as `python -m benchmarks.NAME`: no sys.path edits, and a script
  imports no other script, only the shared `benchmarks.common` (and `research.common`);
* a private name (`_x`) is imported only from a module of the importer's own package;
* the layers of ARCHITECTURE.md: a module imports only modules of its own layer or of layers below it;
* every line of Python in `PYTHON_FOLDERS` shorter than `MAX_COLUMNS` columns.
"""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "lipjax"
MAX_FUNCTION_LINES = 100
MAX_CLI_LINES = 300
MAX_COMMAND_LINES = 20
MAX_COLUMNS = 120  # lines shorter than this
PYTHON_FOLDERS = ("lipjax", "experiments", "benchmarks", "research", "tests")
SCRIPT_PACKAGES = ("benchmarks", "research")  # run as python -m PACKAGE.NAME

# The layers of ARCHITECTURE.md, bottom up: module-name prefix -> layer. The longest matching prefix decides.
LAYERS = {
    # 0: the maths and the leaves (no lipjax imports but within this layer)
    "lipjax.operators": 0, "lipjax.admm": 0, "lipjax.fill": 0, "lipjax.priors": 0, "lipjax.interfaces": 0,
    "lipjax.metrics": 0, "lipjax.zbuffer": 0, "lipjax.viz": 0, "lipjax.shipped": 0, "lipjax.utils": 0,
    "lipjax.resolution": 0, "lipjax.resample": 0, "lipjax.spread": 0, "lipjax.jaxpr_to_onnx": 0,
    "lipjax.console": 0, "lipjax.defaults": 0,
    # 1: frames: data sets, samplers, the synthetic renderer, input checks, hand-crafted completers
    "lipjax.data": 1, "lipjax.pointcloud": 1, "lipjax.inputs": 1, "lipjax.classical": 1,
    # 2: learned models and their files
    "lipjax.model": 2, "lipjax.networks": 2, "lipjax.model_io": 2,
    # 3: running them: inference, the resolver, evaluation, training, export, files and folders on disk
    "lipjax.inference": 3, "lipjax.export": 3, "lipjax.uncertainty": 3, "lipjax.methods": 3, "lipjax.evaluate": 3,
    "lipjax.train": 3, "lipjax.files": 3, "lipjax.onnx_export": 3, "lipjax.crosscheck": 3,
    # 4: the front doors
    "lipjax.cli": 4, "lipjax": 4,
}


def layer_of(module: str) -> int:
    prefixes = [p for p in LAYERS if module == p or module.startswith(p + ".")]
    return LAYERS[max(prefixes, key=len)]


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _imported(name: str, path: Path, node: ast.AST, modules: dict[str, Path]) -> list[str]:
    """The modules an import statement names: `from pkg import sub` names pkg.sub when that is a module."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if not isinstance(node, ast.ImportFrom):
        return []
    if node.level:  # relative: resolved against the importing module's package
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        base = ".".join(package[: len(package) - node.level + 1] + ([node.module] if node.module else []))
    else:
        base = node.module or ""
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]


def import_graph() -> dict[str, set[str]]:
    """module -> the lipjax modules it imports anywhere in its source (module level, functions, classes)."""
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        targets = {t for node in ast.walk(tree) for t in _imported(name, path, node, modules)}
        graph[name] = {t for t in targets if t in modules and t != name}
    return graph


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def long_functions(limit: int = MAX_FUNCTION_LINES) -> list[tuple[str, str, int]]:
    """(file, qualified function name, lines) of every function or method longer than `limit` lines."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        tree = ast.parse(path.read_text(), str(path))

        def walk(node: ast.AST, prefix: str) -> None:
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = child.end_lineno - child.lineno + 1
                    if lines > limit:
                        found.append((rel, prefix + child.name, lines))
                    walk(child, f"{prefix}{child.name}.")
                elif isinstance(child, ast.ClassDef):
                    walk(child, f"{prefix}{child.name}.")
                else:
                    walk(child, prefix)

        walk(tree, "")
    return found


def test_the_checker_sees_a_circle_and_resolves_imports():
    """The checks themselves: a made-up circle is found, and `from pkg import module` names the module."""
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []
    graph = import_graph()
    assert "lipjax.admm" in graph["lipjax"]  # lipjax/__init__.py: from lipjax.admm import ...
    assert "lipjax.data.synthetic.constants" in graph["lipjax.data.synthetic"]


def test_no_import_circles():
    cycles = import_cycles(import_graph())
    assert cycles == [], "import circles among lipjax modules:\n" + "\n".join(" <-> ".join(c) for c in cycles)


def test_no_function_over_the_limit():
    offenders = long_functions()
    assert offenders == [], "\n".join(f"{file}: {name} is {n} lines" for file, name, n in offenders)


def test_the_command_line_is_thin():
    """cli.py parses arguments and hands each command to one library function (ARCHITECTURE.md, "A command")."""
    path = PACKAGE / "cli.py"
    source = path.read_text()
    assert len(source.splitlines()) <= MAX_CLI_LINES
    commands = [f for f in ast.parse(source).body if isinstance(f, ast.FunctionDef) and f.name.startswith("_cmd_")]
    assert len(commands) >= 6
    long = [f"{f.name}: {f.end_lineno - f.lineno + 1} lines" for f in commands
            if f.end_lineno - f.lineno + 1 > MAX_COMMAND_LINES]
    assert long == []


def test_every_line_is_under_the_column_limit():
    long = [f"{path.relative_to(ROOT)}:{i}: {len(line)} columns"
            for folder in PYTHON_FOLDERS for path in sorted((ROOT / folder).rglob("*.py"))
            for i, line in enumerate(path.read_text().splitlines(), 1) if len(line) >= MAX_COLUMNS]
    assert long == [], "\n".join(long)


def test_library_never_imports_experiments_or_benchmarks():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        names = [n for node in ast.walk(tree) for n in _imported(_module_name(path), path, node, {})]
        found += [f"{path.relative_to(ROOT)}: {n}" for n in names
                  if n.split(".")[0] in ("experiments",) + SCRIPT_PACKAGES]
    assert found == []


def test_benchmarks_and_research_are_packages_whose_scripts_share_only_common():
    """`python -m benchmarks.NAME` from the repository root finds lipjax, experiments and benchmarks.common without
    editing sys.path; a script that needs another's helper takes it from benchmarks.common (or research.common)."""
    found = []
    modules = {_module_name(p): p for package in SCRIPT_PACKAGES for p in (ROOT / package).rglob("*.py")}
    scripts = {name.split(".")[-1] for name in modules} - {"__init__", "common"} - set(SCRIPT_PACKAGES)
    for package in SCRIPT_PACKAGES:
        assert (ROOT / package / "__init__.py").is_file(), f"{package}/ is not a package"
        for path in sorted((ROOT / package).rglob("*.py")):
            source, rel = path.read_text(), path.relative_to(ROOT)
            found += [f"{rel}: edits sys.path"] if "sys.path" in source else []
            for node in ast.walk(ast.parse(source, str(path))):
                names = _imported(_module_name(path), path, node, modules)
                found += [f"{rel}: imports {n}" for n in names
                          if n.split(".")[0] in scripts or (n.split(".")[0] in SCRIPT_PACKAGES
                                                            and n.split(".")[1:2] not in ([], ["common"]))]
    assert found == [], "\n".join(found)


def test_private_names_stay_inside_their_package():
    """e.g. lipjax.data.rendered uses lipjax.data.synthetic's public build_scene, not its builders' private names."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = _module_name(path)
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "lipjax":
                private = [a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
                if private and node.module.rsplit(".", 1)[0] != package:
                    found.append(f"{path.relative_to(ROOT)}: from {node.module} import {', '.join(private)}")
    assert found == []


def test_the_default_paths_numbers_are_assigned_in_lipjax_defaults_only():
    """Issue 53: every number and switch of the default path is in one place, lipjax/defaults.py, with its reason and
    the command that re-derives it; a module that uses one imports it from there rather than assigning its own."""
    def assigned(path: Path) -> set[str]:
        targets = [t for node in ast.parse(path.read_text(), str(path)).body
                   for t in (node.targets if isinstance(node, ast.Assign) else
                             [node.target] if isinstance(node, ast.AnnAssign) else [])]
        return {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}

    numbers = assigned(PACKAGE / "defaults.py")
    found = [f"{path.relative_to(ROOT)}: {name}" for path in sorted(PACKAGE.rglob("*.py"))
             if path != PACKAGE / "defaults.py" for name in sorted(assigned(path) & numbers)]
    assert {"TARGET_SPACING_PX", "CROSS_CHECK", "FLIP_SCAN_LINES", "SPREAD_RESIDUALS", "FOLDS"} <= numbers
    assert found == [], "\n".join(found)


def test_every_import_goes_down_the_layers():
    graph = import_graph()
    upward = [f"{m} (layer {layer_of(m)}) imports {t} (layer {layer_of(t)})"
              for m, targets in sorted(graph.items()) for t in sorted(targets) if layer_of(t) > layer_of(m)]
    assert upward == [], "\n".join(upward)
    assert layer_of("lipjax.data.synthetic.indoor") == 1 and layer_of("lipjax.model_io") == 2  # longest prefix
