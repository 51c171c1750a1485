"""benchmarks/README.md is a reference of current figures and benchmarks/record/ the dated record
(issue 56): the reference stays short, each of its rows names a figure, a date, a commit, a command
and a record entry, every link into the record resolves to a file and a heading, and sources cite
the record by file and heading, never by a session."""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
REFERENCE = BENCHMARKS / "README.md"
RECORD = BENCHMARKS / "record"
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
SESSION = re.compile(r"\bsessions?\s+\d", re.I)
DATE = re.compile(r"\b\d{1,2}(–\d{1,2})? (Nov|Dec) 20\d\d\b")
COMMIT = re.compile(r"\b[0-9a-f]{7}\b")


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    """The anchors of the headings of a Markdown page (a repeated heading gains -1, -2, ...)."""
    seen: dict[str, int] = {}
    out = set()
    for line in page.read_text().splitlines():
        if m := re.match(r"#{1,6} (.*)", line):
            a = anchor(m[1])
            out.add(a if a not in seen else f"{a}-{seen[a]}")
            seen[a] = seen.get(a, 0) + 1
    return out


def links(page: Path):
    """(target path, anchor) of every relative link of a Markdown page."""
    for target in LINK.findall(page.read_text()):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):
            continue
        path, _, fragment = target.partition("#")
        yield (page.parent / path).resolve() if path else page, fragment


def test_the_reference_has_at_most_3000_words():
    assert len(REFERENCE.read_text().split()) <= 3000


def test_each_row_of_the_reference_names_a_date_a_commit_a_command_and_its_record():
    rows = [line for line in REFERENCE.read_text().splitlines()
            if line.startswith("| ") and not line.startswith("| capability")]
    assert len(rows) >= 40
    for row in rows:
        capability, figure, date, code, command, record = row.strip("|").split(" | ")
        assert figure.strip() and DATE.search(date), row
        assert COMMIT.search(code), row
        assert command.startswith("`"), row
        assert "(record/" in record, row


@pytest.mark.parametrize("page", [REFERENCE, *sorted(RECORD.glob("*.md"))], ids=lambda p: p.name)
def test_every_link_into_the_record_resolves_to_a_file_and_a_heading(page):
    for path, fragment in links(page):
        if RECORD not in path.parents and path != REFERENCE:
            continue
        assert path.is_file(), f"{page.name}: {path} does not exist"
        assert not fragment or fragment in anchors(path), f"{page.name}: no heading #{fragment} in {path.name}"


def test_the_reference_links_every_record_file():
    linked = {path.name for path, _ in links(REFERENCE) if RECORD in path.parents}
    index = {path.name for path, _ in links(RECORD / "README.md") if path.parent == RECORD}
    assert index == {p.name for p in RECORD.glob("*.md")} - {"README.md"}
    assert "README.md" in linked and linked - {"README.md"} <= index


def test_no_source_cites_a_session_pending_the_python_and_crates_edits_of_citations_md():
    """Fails until the python/ and crates/ lines listed in /work/notes/citations.md are applied."""
    sources = [*ROOT.glob("python/**/*.py"), *ROOT.glob("crates/**/*.rs"), *ROOT.glob("tests/**/*.py"),
               *BENCHMARKS.glob("*.py")]
    cited = [f"{p.relative_to(ROOT)}:{n}" for p in sources
             for n, line in enumerate(p.read_text().splitlines(), 1) if SESSION.search(line)]
    assert not cited, f"sources cite a session: {cited}"
