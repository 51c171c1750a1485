"""The modules of prebo import one another without a circle: each module's imports, at any depth
(inside functions too, where a circle hides), relative ones resolved, form an acyclic graph.

An edge goes to the module an import names: `from .x import f` to x, `from . import x` to x when
x is a module, `from .. import f` to the package. That a submodule's import first runs its
package's __init__ is Python's machinery, not a dependency of the importer, and is no edge.
"""
import ast

import pytest

from conftest import ROOT

PACKAGE = ROOT / "python" / "prebo"


def modules() -> dict:
    """Each module's dotted name -> (its file, whether it is a package's __init__); a compiled
    module (prebo._core) by its stub, which imports nothing of prebo."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")) + sorted(PACKAGE.rglob("*.pyi")):
        parts = ("prebo",) + path.relative_to(PACKAGE).with_suffix("").parts
        init = parts[-1] == "__init__"
        found.setdefault(".".join(parts[:-1] if init else parts), (path, init))
    return found


def imports(name: str, path, init: bool, known) -> set:
    """The prebo modules module `name` imports, anywhere in its file."""
    package = name if init else name.rpartition(".")[0]
    edges = set()
    if path.suffix == ".pyi":
        return edges
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            edges |= {a.name for a in node.names if a.name in known}
        elif isinstance(node, ast.ImportFrom):
            base = package.rsplit(".", node.level - 1)[0] if node.level else ""
            target = ".".join(p for p in (base, node.module) if p)
            for a in node.names:
                sub = f"{target}.{a.name}"
                if sub in known:
                    edges.add(sub)
                elif target in known:
                    edges.add(target)
    edges.discard(name)
    return edges


def graph() -> dict:
    """The import graph of prebo: module -> the modules it imports."""
    known = modules()
    return {name: imports(name, path, init, known) for name, (path, init) in known.items()}


def cycle(g: dict) -> list | None:
    """A circle of imports in `g` as [a, b, ..., a], or None (depth-first search)."""
    state, stack = {}, []

    def visit(m):
        state[m] = "open"
        stack.append(m)
        for n in sorted(g[m]):
            if state.get(n) == "open":
                return stack[stack.index(n):] + [n]
            if n not in state:
                found = visit(n)
                if found:
                    return found
        state[m] = "done"
        stack.pop()
        return None

    for m in sorted(g):
        if m not in state:
            found = visit(m)
            if found:
                return found
    return None


def test_the_scan_sees_imports_inside_functions_and_relative_ones():
    g = graph()
    assert "prebo.optimise.settings" in g["prebo.io.toml"]  # from ..optimise.settings import ...
    assert "prebo.optimise.driver" in g["prebo.optimise"]  # from .driver import ... in __init__
    assert "prebo.level.evaluate" in g["prebo.cli.result"]  # inside a function
    assert cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]


def test_the_optimiser_imports_without_a_circle():
    """The six modules of prebo.optimise that imported one another in a circle, hidden by imports
    inside functions (checkpoint → schedule → checkpoint, methods → checkpoint → convergence →
    methods, ...; issue 38), stay apart."""
    g = {m: {n for n in e if n.startswith("prebo.optimise.")} for m, e in graph().items()
         if m.startswith("prebo.optimise.")}
    found = cycle(g)
    assert found is None, "import circle: " + " → ".join(found)


def test_no_module_imports_itself_through_others():
    found = cycle(graph())
    assert found is None, "import circle: " + " → ".join(found)


def test_one_process_imports_nothing_of_mpi():
    """Without an MPI launcher prebo runs as one process and never imports mpi4py (parallel.py),
    through a whole command."""
    import os
    import subprocess
    import sys
    env = {k: v for k, v in os.environ.items() if k not in ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "PMIX_SIZE")}
    code = ("import sys, prebo.cli; status = prebo.cli.main(['energy', 'tests/data/ecgpack/ecgpack-Li7-100.inout.txt']); "
            "print('mpi4py' in sys.modules, status)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT)
    assert r.stdout.split()[-2:] == ["False", "0"], r.stdout + r.stderr
