"""The Rust core's module graph runs one way, as tests/test_imports.py checks for Python.

crates/prebo-core/src/lib.rs lists the layers in its module docs ("N. title: `path`, ...", with
`a::{b, c}` for several paths); a module belongs to the longest listed path that is it or contains
it. Every `use`, `crate::…` and `super::…` path of the library (test modules aside) must go to a
module of the same or an earlier layer, and the modules must form no circle.
"""
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "crates" / "prebo-core" / "src"


def module_of(path: Path, src: Path) -> tuple[str, ...]:
    """`a::b` of src/a/b.rs or src/a/b/mod.rs; () for lib.rs."""
    parts = path.relative_to(src).with_suffix("").parts
    return tuple(parts[:-1]) if parts[-1] in ("mod", "lib") else tuple(parts)


def library_files(src: Path) -> dict[tuple[str, ...], str]:
    """Each module's source without comments, string literals and `#[cfg(test)]` items; test
    files (`tests.rs`, `*_tests.rs`) and included fragments (`include!`) left out."""
    included = {m for f in src.rglob("*.rs") for m in re.findall(r'include!\("([^"]+)"\)', f.read_text())}
    out = {}
    for f in sorted(src.rglob("*.rs")):
        if f.name == "tests.rs" or f.name.endswith("_tests.rs") or f.name in included:
            continue
        text = re.sub(r'"(?:\\.|[^"\\])*"', '""', f.read_text())
        text = re.sub(r"//[^\n]*", "", text)
        out[module_of(f, src)] = inline_super(without_tests(text))
    return out


def inline_super(text: str) -> str:
    """`text` with `super::` inside an inline `mod … { … }` (e.g. one per instruction set, made by
    a macro) written `self::`: there it names the file's own module."""
    for match in reversed(list(re.finditer(r"\bmod\s+\$?\w+\s*\{", text))):
        depth, i = 0, match.end() - 1
        while True:
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            if depth == 0:
                break
            i += 1
        text = text[:match.end()] + re.sub(r"\bsuper::", "self::", text[match.end():i]) + text[i:]
    return text


def without_tests(text: str) -> str:
    """`text` without each item behind `#[cfg(test)]` (a `mod … { … }` to its closing brace, else
    up to the next `;`)."""
    while (at := text.find("#[cfg(test)]")) >= 0:
        rest = text[at + len("#[cfg(test)]"):]
        brace, semi = rest.find("{"), rest.find(";")
        if brace < 0 or 0 <= semi < brace:
            text = text[:at] + rest[semi + 1:]
            continue
        depth, i = 0, brace
        while True:
            depth += {"{": 1, "}": -1}.get(rest[i], 0)
            if depth == 0:
                break
            i += 1
        text = text[:at] + rest[i + 1:]
    return text


def expand(tree: str) -> list[str]:
    """The paths of a use tree: `a::{b, c::{d, e}}` -> a::b, a::c::d, a::c::e."""
    tree = re.sub(r"\s+", "", tree)
    if "{" not in tree:
        return [tree]
    head, inner = tree[: tree.index("{")], tree[tree.index("{") + 1: tree.rindex("}")]
    parts, depth, start = [], 0, 0
    for i, c in enumerate(inner):
        depth += {"{": 1, "}": -1}.get(c, 0)
        if c == "," and depth == 0:
            parts.append(inner[start:i])
            start = i + 1
    parts.append(inner[start:])
    return [head + p for part in parts if part for p in expand(part)]


def edges(src: Path = SRC) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
    """For each library module, the modules its paths name (the longest module prefix of each)."""
    files = library_files(src)
    known = set(files)
    graph = {}
    for module, text in files.items():
        paths = [p for tree in re.findall(r"\buse\s+([^;]+);", text) for p in expand(tree)]
        paths += re.findall(r"(?<![\w:])((?:crate|super|self)(?:::\w+)+)", text)
        targets = set()
        for path in paths:
            segments = path.split(" as ")[0].split("::")
            if segments[0] == "crate":
                absolute = list(segments[1:])
            elif segments[0] == "self":
                absolute = list(module) + segments[1:]
            elif segments[0] == "super":
                base = list(module)
                while segments and segments[0] == "super":
                    base, segments = base[:-1], segments[1:]
                absolute = base + segments
            elif module + (segments[0],) in known:  # a child module, by its name
                absolute = list(module) + segments
            else:
                continue
            for n in range(len(absolute), 0, -1):
                if tuple(absolute[:n]) in known:
                    if tuple(absolute[:n]) != module:
                        targets.add(tuple(absolute[:n]))
                    break
        graph[module] = targets
    return graph


def layers(src: Path = SRC) -> dict[tuple[str, ...], int]:
    """The listed paths of lib.rs's layer list with their layer numbers."""
    doc = "\n".join(line[4:] for line in (src / "lib.rs").read_text().splitlines() if line.startswith("//! "))
    out = {}
    for number, body in re.findall(r"^(\d+)\. [^:\n]*:(.*?)(?=^\d+\. |\Z)", doc, re.M | re.S):
        for tree in re.findall(r"`([^`]+)`", body):
            for path in expand(tree):
                out[tuple(path.split("::"))] = int(number)
    return out


def layer_of(module: tuple[str, ...], listed: dict[tuple[str, ...], int]) -> int | None:
    for n in range(len(module), 0, -1):
        if module[:n] in listed:
            return listed[module[:n]]
    return None


def circles(graph: dict) -> list[list[tuple[str, ...]]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def name(module: tuple[str, ...]) -> str:
    return "::".join(module) or "crate"


def test_the_layer_list_names_every_module_and_only_modules():
    listed, modules = layers(), set(library_files(SRC)) - {()}
    assert len(set(listed.values())) >= 5, f"lib.rs lists no layers: {listed}"
    assert [m for m in sorted(listed) if m not in modules] == []
    assert [name(m) for m in sorted(modules) if layer_of(m, listed) is None] == []


def test_every_module_uses_only_its_own_layer_and_earlier_ones():
    listed = layers()
    upward = [f"{name(a)} (layer {layer_of(a, listed)}) uses {name(b)} (layer {layer_of(b, listed)})"
              for a, targets in sorted(edges().items()) if a for b in sorted(targets)
              if layer_of(b, listed) > layer_of(a, listed)]
    assert upward == []


def test_no_import_circle():
    assert [[name(m) for m in c] for c in circles(edges())] == []
