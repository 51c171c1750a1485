"""The basis-family registry (issue 14): one Family object per basis type, looked up by name."""
import numpy as np
import pytest

import prebo
from prebo.basis import FAMILIES, Basis, family
from prebo.errors import InputError
from test_imports import graph


def test_families_by_name():
    assert list(FAMILIES) == ["pecg", "ecg-gvr", "fecg"]
    assert family("pecg").parameters == ("A", "c_A")
    assert family("ecg-gvr").parameters == ("A", "u", "K", "c_A")
    assert family("fecg").parameters == ("A", "s", "c_A")
    assert [family(k).conserves_L for k in FAMILIES] == [True, True, False]
    assert all(family(k).name == k for k in FAMILIES)


@pytest.mark.parametrize("name", ["gvr", "ECG", None, 3])
def test_unknown_family_names_the_known_ones(name):
    with pytest.raises(InputError, match="pecg, ecg-gvr, fecg"):
        family(name)
    with pytest.raises(InputError, match="pecg, ecg-gvr, fecg"):
        Basis.empty(prebo.System(["p", "e"]), name)


def test_check_state_is_the_families_rule():
    p_state = prebo.System(["p", "e"], N=1, parity=-1).state
    with pytest.raises(InputError, match="N = 0, parity \\+1"):
        family("pecg").check_state(p_state)
    family("ecg-gvr").check_state(p_state)
    with pytest.raises(InputError, match="natural parity"):
        family("ecg-gvr").check_state(prebo.System(["p", "e"], N=1, parity=1).state)
    family("fecg").check_state(prebo.System(["p", "e"], N=0, parity=-1).state)
    with pytest.raises(InputError, match="N = 0 only"):  # the core evaluates no other
        family("fecg").check_state(prebo.System(["p", "e"], N=1, parity=1).state)


def test_basis_knows_its_family_and_keeps_its_kind():
    s = prebo.System(["p", "e"], N=1, parity=-1)
    b = Basis(s, np.eye(2)[None], [1.0], kind="ecg-gvr", u=[[1.0, -1.0]], K=[2])
    assert b.family is family("ecg-gvr") and b.kind == "ecg-gvr"
    assert b.K.dtype == np.uint32 and set(b.parameters) == {"u", "K"}


H = prebo.System(["p", "e"])
P = prebo.System(["p", "e"], N=1, parity=-1)
ONE = np.eye(2)[None]  # one 2 x 2 exponent matrix
NAN, INF = float("nan"), float("inf")


def gvr(u, K=(2,)):
    return Basis(P, ONE, [1.0], kind="ecg-gvr", u=u, K=K)


def fecg(s):
    return Basis(H, ONE, [1.0], kind="fecg", s=s)


@pytest.mark.parametrize("call, message", [
    (lambda: Basis(None, ONE, [1.0]), "Basis: system = None: must be a prebo.System"),
    (lambda: Basis.empty(None), "Basis.empty: system = None: must be a prebo.System"),
    (lambda: Basis(["p", "e"], ONE, [1.0]), "Basis: system = ['p', 'e']: must be a prebo.System"),
    (lambda: Basis(H, None, [1.0]),
     "Basis: A = None: must be 2 x 2 exponent matrices, one per function (real numbers)"),
    (lambda: Basis(H, "x", [1.0]), "Basis: A = 'x': must be 2 x 2 exponent matrices"),
    (lambda: Basis(H, np.eye(3)[None], [1.0]), "Basis: A = an array of shape (1, 3, 3): must be 2 x 2 exponent"),
    (lambda: Basis(H, ONE, None), "Basis: c_A = None: must be one number per function (real numbers)"),
    (lambda: Basis(H, ONE, [float("nan")]), "Basis: c_A[0] = nan: must be a finite number"),
    (lambda: Basis(H, ONE, [float("inf")]), "Basis: c_A[0] = inf: must be a finite number"),
    (lambda: Basis(H, [[1.0, 0.0], [0.0, float("nan")]], [1.0]), "Basis: A[0, 1, 1] = nan: must be a finite number"),
    (lambda: Basis(H, ONE, [1.0], channels=5), "Basis: channels = 5: must be a list of coordinate-set names"),
    (lambda: Basis(H, ONE, [1.0], channels=["hpc:0", "hpc:1"]), "basis: 1 functions but 2 channels"),
    (lambda: Basis.load(5), "Basis.load: path = 5: must be a file name (a str or path)"),
    (lambda: Basis.empty(H).save(None), "Basis.save: path = None: must be a file name (a str or path)"),
    (lambda: gvr("x"), "Basis: u = 'x': must be 2 numbers per function (real numbers)"),
    (lambda: gvr([["a", "b", "c", "d"]]), "Basis: u = [['a', 'b', 'c', 'd']]: must be 2 numbers per function"),
    (lambda: gvr([[1.0, NAN]]), "Basis: u[0, 1] = nan: must be a finite number"),
    (lambda: gvr([[INF, 1.0]]), "Basis: u[0, 0] = inf: must be a finite number"),
    (lambda: gvr([[1.0, -1.0]], K="x"), "Basis: K = 'x': must be one number per function (real numbers)"),
    (lambda: fecg([[[0.0, 0.0, NAN], [0.0, 0.0, 0.0]]]), "Basis: s[0, 0, 2] = nan: must be a finite number"),
    (lambda: fecg([[[0.0, 0.0, 0.0], [-INF, 0.0, 0.0]]]), "Basis: s[0, 1, 0] = -inf: must be a finite number"),
    (lambda: fecg("x"), "Basis: s = 'x': must be 2 x 3 numbers per function (real numbers)"),
    (lambda: Basis(H, ONE, [1.0], coefficients=[1.0, 2.0]), "basis: 1 functions but 2 coefficients"),
    (lambda: Basis(H, ONE, [1.0], coefficients=[NAN]), "Basis: coefficients[0] = nan: must be a finite number"),
])
def test_wrong_arguments_are_refused_at_construction(call, message):
    """A new user's calls raised AttributeError, TypeError or ValueError, or took a NaN c_A that
    failed only when the basis was evaluated."""
    with pytest.raises(InputError) as exc:
        call()
    assert message in str(exc.value)


def test_coefficients_of_the_wrong_length_are_refused_when_saved(tmp_path):
    """Coefficients set after construction to a length other than the number of functions were
    saved and then refused by Basis.load."""
    w, mu = np.array([1.0, -1.0]), H.cm_vector
    b = Basis(H, [np.outer(w, w) + np.outer(mu, mu), 2 * np.outer(w, w) + np.outer(mu, mu)], [1.0, 1.0])
    b.coefficients = np.ones(3)
    with pytest.raises(InputError, match="Basis.save: 2 functions but 3 coefficients"):
        b.save(tmp_path / "basis.json")
    assert not (tmp_path / "basis.json").exists()
    with pytest.raises(InputError, match="Basis.to_dict: 2 functions but 3 coefficients"):
        b.to_dict()
    b.coefficients = [0.6, 0.8]
    b.save(tmp_path / "basis.json")
    assert Basis.load(tmp_path / "basis.json").coefficients.tolist() == [0.6, 0.8]


def test_no_module_outside_the_basis_package_tests_the_family_name():
    """Family behaviour is dispatched through the Family object: no comparison with a family's
    name (`kind == "fecg"`, `kind in ("pecg", ...)`) anywhere in prebo outside prebo/basis/."""
    import ast
    from pathlib import Path

    root = Path(prebo.__file__).parent
    found = []
    for path in root.rglob("*.py"):
        if path.parent.name == "basis":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare):
                names = {c.value for side in (node.left, *node.comparators) for c in ast.walk(side)
                         if isinstance(c, ast.Constant)}
                if names & set(FAMILIES):
                    found.append(f"{path.relative_to(root)}:{node.lineno}")
    assert not found


def test_no_module_outside_the_basis_package_imports_a_family_module():
    """Families are reached through the registry (prebo.basis.family(name)): no module outside
    prebo/basis/ imports prebo.basis.pecg, .ecg_gvr or .fecg, inside functions or not (test_imports.graph)."""
    modules = {type(f).__module__ for f in FAMILIES.values()}  # prebo.basis.pecg, .ecg_gvr, .fecg
    found = [f"{m} imports {', '.join(sorted(e & modules))}" for m, e in graph().items()
             if m.split(".")[:2] != ["prebo", "basis"] and e & modules]
    assert not found
