"""docs/architecture.md is true: every file, folder and code symbol it names in backticks exists.

A name with a slash or a file suffix is a path: relative to the repository, to the Python
package (python/ or python/prebo), to a crate or its source (crates/*, crates/*/src); a bare file
name must be some file of the package or the crates. `<name>` stands for any folder. A code name
(`Family::damped`, `expectation.OPERATORS`, `Kind`, `dispatch!`) must be a module of the package
or be defined in the sources or tests: its last part a Python def/class/assignment or a Rust item
(or one of Rust's own types), and a qualifier that names a module, a type or a trait must hold
that part.
"""
import functools
import re

import pytest

from conftest import ROOT

DOC = ROOT / "docs" / "architecture.md"
PACKAGE = ROOT / "python" / "prebo"
CRATES = sorted((ROOT / "crates").glob("*/src"))
BASES = [ROOT, ROOT / "python", PACKAGE, *(c.parent for c in CRATES), *CRATES]
SUFFIXES = (".py", ".pyi", ".rs", ".md", ".toml", ".json", ".yml", ".yaml")
SOURCES = (sorted(PACKAGE.rglob("*.py")) + sorted(PACKAGE.rglob("*.pyi")) + sorted(ROOT.glob("crates/*/src/**/*.rs"))
           + sorted((ROOT / "tests").glob("*.py")))
RUST = {"Option", "Result", "Vec", "None", "Some"}
IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
CODE = re.compile(rf"^{IDENT}((::|\.){IDENT})*(!|\(.*\))?$")


def named() -> list[str]:
    """The backticked names of the page, once each, in order."""
    text = re.sub(r"```.*?```", "", DOC.read_text(), flags=re.S)
    return list(dict.fromkeys(re.findall(r"`([^`\n]+)`", text)))


def is_path(name: str) -> bool:
    return " " not in name and ("/" in name or name.endswith(SUFFIXES))


def exists(path: str) -> bool:
    """Whether `path` is a file or folder of the repository (`<...>` matching any folder)."""
    pattern = re.sub(r"<[^>]+>", "*", path.rstrip("/"))
    if "/" not in path:
        return any(p.name == pattern for base in (PACKAGE, *CRATES) for p in base.rglob(pattern))
    return any(any(base.glob(pattern)) for base in BASES)


@functools.cache
def definitions() -> tuple[set, dict]:
    """(every defined name, file stem or type name -> the names its file or impl blocks hold)."""
    defined, holds = set(), {}
    item = re.compile(rf"\b(?:def|class|fn|struct|enum|trait|const|static|type|mod|macro_rules!)\s+({IDENT})")
    for path in SOURCES:
        text = path.read_text()
        names = set(item.findall(text))
        names |= set(re.findall(rf"^\s*({IDENT})\s*(?::[^=\n]*)?=", text, re.M))  # assignments, fields
        names |= set(re.findall(rf"^({IDENT})\s*:", text, re.M)) if path.suffix == ".pyi" else set()  # stubs
        names |= set(re.findall(rf"^\s*({IDENT})\s*[,({{]", text, re.M)) if path.suffix == ".rs" else set()  # variants
        names |= set(re.findall(rf"pub\s+({IDENT})\s*:", text))  # Rust fields
        defined |= names
        stem = path.parent.name if path.stem in ("__init__", "mod") else path.stem
        holds.setdefault(stem, set()).update(names)
        for kind, owner in re.findall(rf"\b(struct|enum|trait|class)\s+({IDENT})", text):
            holds.setdefault(owner, set()).update(names)
    return defined, holds


@pytest.mark.parametrize("name", [n for n in named() if is_path(n)])
def test_every_path_it_names_exists(name):
    assert exists(name), f"docs/architecture.md names {name!r}, which is not a file or folder of prebo"


@pytest.mark.parametrize("name", [n for n in named() if not is_path(n) and CODE.match(n)])
def test_every_code_name_it_names_is_defined(name):
    defined, holds = definitions()
    bare = re.sub(r"(!|\(.*\))$", "", name)
    module = ROOT / "python" / bare.replace(".", "/")
    if module.with_suffix(".py").exists() or (module / "__init__.py").exists() or bare in RUST:
        return
    parts = re.split(r"::|\.", bare)
    assert parts[-1] in defined, f"docs/architecture.md names {name!r}: {parts[-1]!r} is defined nowhere"
    for owner, part in zip(parts, parts[1:]):
        if owner in holds:
            assert part in holds[owner], f"docs/architecture.md names {name!r}: {owner!r} holds no {part!r}"
