"""MkDocs hooks of the documentation site (mkdocs.yml): the README as a page, the pictures the
pages show from elsewhere in the repository, links that leave docs/, and the command-line
reference, written from `prebo.cli.parser()` at every build so that it cannot go stale.

The pages keep the relative links that work where they stand in the repository (GitHub, an
editor); here each is pointed at the page or file the site has for it: `../README.md` at the
README page, `docs/X.md` from the README at the page X, a picture at its copy under
`repository/`. A link to another file of the repository (source, benchmarks/README.md) becomes
its path as plain text; a link to a file that does not exist is left for `--strict` to refuse.
"""
import argparse
import html
import posixpath
import re
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
README = "readme.md"                         # the README's page in the site
PICTURES = "repository"                      # where pictures from outside docs/ are copied
CLI = "reference/cli.md"
LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```.*?^```)", re.S | re.M)


def repository_path(src_uri: str) -> str:
    """The path in the repository of the page at `src_uri` in the site."""
    return "README.md" if src_uri == README else f"docs/{src_uri}"


def site_path(path: str) -> str | None:
    """The site's file for the repository file `path`, or None if the site has none."""
    if path == "README.md":
        return README
    if path.startswith("docs/"):
        return path[len("docs/"):]
    return None


def outside_targets(page: str, markdown: str):
    """(match, repository path) of every link of the page `page` (a repository path) that leaves
    docs/ (from the README: every link), code blocks left out."""
    for part in FENCE.split(markdown)[::2]:
        for match in LINK.finditer(part):
            target = match[3].split("#")[0]
            if not target or re.match(r"[a-z][a-z0-9+.-]*:|/", target):
                continue
            path = posixpath.normpath(posixpath.join(posixpath.dirname(page), target))
            if path.startswith("../") or (page.startswith("docs/") and path.startswith("docs/")):
                continue
            yield match, path


def on_files(files, config):
    """Add the README, the pictures the pages show from outside docs/, and the CLI reference."""
    files.append(File.generated(config, README, abs_src_path=str(ROOT / "README.md")))
    pages = [(repository_path(f.src_uri), f.content_string) for f in files.documentation_pages()]
    for page, markdown in pages:
        for match, path in outside_targets(page, markdown):
            if match[1] and site_path(path) is None and (ROOT / path).is_file():
                uri = f"{PICTURES}/{path}"
                if files.get_file_from_path(uri) is None:
                    files.append(File.generated(config, uri, abs_src_path=str(ROOT / path)))
    files.append(File.generated(config, CLI, content=cli_reference()))
    return files


def on_page_markdown(markdown, page, config, files):
    """Point the page's links that leave docs/ at the site's page or file for them."""
    here = repository_path(page.file.src_uri)

    def relink(match: re.Match, path: str) -> str:
        image, text, target = match[1], match[2], match[3]
        anchor = target[len(target.split("#")[0]):]
        uri = site_path(path) or (f"{PICTURES}/{path}" if image else None)
        if uri is not None and files.get_file_from_path(uri) is not None:
            return f"{image}[{text}]({posixpath.relpath(uri, posixpath.dirname(page.file.src_uri) or '.')}{anchor})"
        if not image and (ROOT / path).exists():
            return f"`{path}`" if text.strip("`") == target else f"{text} (`{path}`)"
        return match[0]

    links = {match[0]: relink(match, path) for match, path in outside_targets(here, markdown)}
    parts = FENCE.split(markdown)
    parts[::2] = [LINK.sub(lambda m: links.get(m[0], m[0]), part) for part in parts[::2]]
    return "".join(parts)


def cli_reference() -> str:
    """The command-line reference: each subcommand's usage, and its arguments in a table."""
    from prebo.cli import parser

    top = parser()
    (commands,) = [a for a in top._actions if isinstance(a, argparse._SubParsersAction)]
    helps = {c.dest: c.help for c in commands._choices_actions}
    lines = ["# Command line", "",
             "Every `prebo` command and its arguments, as `prebo COMMAND --help` prints them "
             "(written from `prebo.cli.parser()` when the site is built).", "",
             "```text", top.format_usage().strip(), "```", ""]
    for name, sub in commands.choices.items():
        lines += [f"## prebo {name}", "", escape(helps[name][:1].upper() + helps[name][1:]) + ".", "",
                  "```text", sub.format_usage().strip(), "```", "",
                  "| argument | meaning |", "|---|---|"]
        formatter = sub._get_formatter()
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            lines.append(f"| `{formatter._format_action_invocation(action)}` "
                         f"| {escape(formatter._expand_help(action) if action.help else '')} |")
        lines.append("")
    return "\n".join(lines)


def escape(text: str) -> str:
    """`text` as the plain text of a Markdown table cell."""
    return re.sub(r"([\\`*_\[\]|])", r"\\\1", html.escape(text, quote=False)).replace("\n", " ")
