"""The stub python/prebo/_core.pyi describes the compiled module: the same public names, and for
every function, the Engine constructor and every Engine method the same parameters (names,
order, which have defaults, the defaults' values) as the module's text signatures."""
import ast
import inspect
from pathlib import Path

import pytest

from prebo import _core

STUB = Path(__file__).resolve().parents[1] / "python" / "prebo" / "_core.pyi"
TREE = ast.parse(STUB.read_text())
ALIASES = {"Params", "Matrices"}  # type aliases of the stub only


def stub_parameters(node: ast.FunctionDef) -> list[tuple[str, object]]:
    """(name, default or inspect.Parameter.empty) of a stub function, without self."""
    args = node.args.posonlyargs + node.args.args
    defaults = [inspect.Parameter.empty] * (len(args) - len(node.args.defaults))
    defaults += [ast.literal_eval(d) for d in node.args.defaults]
    out = [(a.arg, d) for a, d in zip(args, defaults) if a.arg != "self"]
    for a, d in zip(node.args.kwonlyargs, node.args.kw_defaults):
        out.append((a.arg, inspect.Parameter.empty if d is None else ast.literal_eval(d)))
    return out


def module_parameters(obj) -> list[tuple[str, object]]:
    sig = inspect.signature(obj)
    return [(p.name, p.default) for p in sig.parameters.values() if p.name != "self"]


def top_level() -> dict[str, ast.AST]:
    out = {}
    for node in TREE.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            out[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            out[node.target.id] = node
        elif isinstance(node, ast.Assign):
            out.update({t.id: node for t in node.targets})
    return out


def test_stub_and_module_have_the_same_public_names():
    stub = {n for n in top_level() if not n.startswith("_")} - ALIASES
    module = {n for n in dir(_core) if not n.startswith("_")}
    assert stub == module, f"only in the stub: {stub - module}; only in the module: {module - stub}"


FUNCTIONS = [n for n, node in top_level().items() if isinstance(node, ast.FunctionDef)]


@pytest.mark.parametrize("name", FUNCTIONS)
def test_function_parameters_match(name):
    assert stub_parameters(top_level()[name]) == module_parameters(getattr(_core, name))


ENGINE = top_level()["Engine"]
METHODS = [n for n in ENGINE.body if isinstance(n, ast.FunctionDef)]


@pytest.mark.parametrize("node", METHODS, ids=[m.name for m in METHODS])
def test_engine_members_match(node):
    properties = {d.id for d in node.decorator_list if isinstance(d, ast.Name)}
    if node.name == "__init__":
        assert stub_parameters(node) == module_parameters(_core.Engine)
    elif "property" in properties:
        assert isinstance(inspect.getattr_static(_core.Engine, node.name), type(_core.Engine.n))
    else:
        assert stub_parameters(node) == module_parameters(getattr(_core.Engine, node.name))


def test_engine_has_no_member_missing_from_the_stub():
    stub = {m.name for m in METHODS} - {"__init__"}
    module = {n for n in vars(_core.Engine) if not n.startswith("_")}
    assert module == stub


def test_every_stub_member_is_documented():
    for node in [*(top_level()[n] for n in FUNCTIONS), ENGINE, *METHODS]:
        assert ast.get_docstring(node), node.name


def test_package_is_marked_typed():
    assert (STUB.parent / "py.typed").is_file()
