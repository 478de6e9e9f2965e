"""The import graph of bifilar/ and validate/: no cycle, and the layers import only downwards.

Every import statement counts, at module level and inside functions: an import moved into a function
to dodge a cycle still ties the two modules together (issue 36). The graph is read from the source with
`ast`, nothing is imported, so a cycle is found even where Python would resolve it at run time.
Layers: `bifilar` never imports `validate`; rig < motion < identification, sweep (bifilar/); the
report pages (validate/report) are below the commands (validate/commands).
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("bifilar", "validate")


def _within(module, package):
    return module == package or module.startswith(package + ".")


def _modules():
    """Dotted module name -> (path, is_package) for every .py file under the project's packages."""
    found = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            is_package = parts[-1] == "__init__"
            if is_package:
                parts.pop()
            found[".".join(parts)] = (path, is_package)
    return found


def _target(name, modules):
    """The module a dotted name lands in: the longest prefix that is a module of ours, else None."""
    parts = name.split(".")
    while parts:
        candidate = ".".join(parts)
        if candidate in modules:
            return candidate
        parts.pop()
    return None


def _imports(module, source, is_package, modules):
    """The set of our modules that `module` (its text `source`) imports anywhere in its body."""
    return _edges(module, ast.walk(ast.parse(source, module)), is_package, modules)


def _edges(module, nodes, is_package, modules):
    """The set of our modules that the import statements among `nodes` (of `module`) import."""
    package = module if is_package else module.rpartition(".")[0]
    edges = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module
            # `from pkg import x` names the submodule pkg.x when x is one, else an attribute of pkg.
            names = [f"{source}.{alias.name}" for alias in node.names]
        else:
            continue
        for name in names:
            target = _target(name, modules)
            if target is not None and target != module:
                edges.add(target)
                edges.update(_parents(target, module, modules))
    return edges


def _parents(target, module, modules):
    """The packages Python runs on the way to `target`: those above it that `module` is not inside of.

    Importing bifilar.rig.checks from bifilar.bodies runs bifilar/rig/__init__.py first, and so whatever that
    imports; from within bifilar.rig the package is already being imported, so that is no edge.
    """
    parts = target.split(".")[:-1]
    while parts:
        package = ".".join(parts)
        if package in modules and not _within(module, package):
            yield package
        parts.pop()


def _graph():
    """Module -> the set of our modules it imports."""
    modules = _modules()
    return {module: _imports(module, path.read_text(), is_package, modules)
            for module, (path, is_package) in modules.items()}


GRAPH = _graph()


def _components(graph):
    """Strongly connected components (Tarjan, iterative) with more than one module."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def _violations(lower, higher):
    return sorted(
        f"{module} -> {target}"
        for module, targets in GRAPH.items()
        if _within(module, lower)
        for target in targets
        if any(_within(target, package) for package in higher)
    )


def test_graph_is_read():
    # A guard on the reader itself: every module is seen, with a known edge; imports inside functions,
    # relative ones, submodules named in `from pkg import x`, and the packages run on the way all count.
    assert len(GRAPH) > 100 and "bifilar.rig.so3" in GRAPH["bifilar.rig.statics"]
    source = "def f():\n    from ..rig import so3, Rig\n    import bifilar.motion.kane\n"
    assert _imports("bifilar.sweep.x", source, False, _modules()) == {
        "bifilar.rig", "bifilar.rig.so3", "bifilar.motion", "bifilar.motion.kane"}


def test_no_import_cycle():
    cycles = _components(GRAPH)
    assert not cycles, "import cycles (each a set of modules that import one another):\n" + "\n".join(
        "  " + " <-> ".join(cycle) for cycle in cycles
    )


def test_bifilar_never_imports_validate():
    assert _violations("bifilar", ["validate"]) == []


def test_bifilar_hides_no_import_of_its_own_in_a_function():
    # An import inside a function is for a heavy optional dependency (dask, numba's internals), never
    # to dodge a cycle between our own modules.
    modules, hidden = _modules(), set()
    for module, (path, is_package) in modules.items():
        if not _within(module, "bifilar"):
            continue
        for function in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
                inner = (node for statement in function.body for node in ast.walk(statement))
                hidden.update(f"{module}.{function.name} -> {target}"
                              for target in _edges(module, inner, is_package, modules))
    assert sorted(hidden) == []


def test_rig_is_below_motion_identification_sweep():
    assert _violations("bifilar.rig", ["bifilar.motion", "bifilar.identification", "bifilar.sweep"]) == []


def test_motion_is_below_identification_sweep():
    assert _violations("bifilar.motion", ["bifilar.identification", "bifilar.sweep"]) == []


def test_report_is_below_commands():
    assert _violations("validate.report", ["validate.commands"]) == []
