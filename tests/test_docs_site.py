"""The documentation site (mkdocs.yml) as `mkdocs build --strict` builds it: a page for every file of
docs/ and the README, a documented heading for every public name of `prebo`, every subcommand and
option of the parser in the CLI reference; and the built site in headless Chromium: the index, the
tutorial with its picture and the API page render their headings, every internal link of theirs
points to a built file, and nothing is fetched from another host."""
import functools
import html
import http.server
import importlib
import inspect
import json
import os
import re
import shutil
import subprocess
import sys
import threading
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

import prebo
from prebo.cli import parser

from conftest import ROOT

CHROMIUM = shutil.which("chromium")
PAGES = {"index.md": "", "tutorial.md": "tutorial/", "reference/api.md": "reference/api/"}


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built strictly into a tmp folder; a proxy at a closed port fails any download."""
    out = tmp_path_factory.mktemp("site")
    closed = "http://127.0.0.1:9"
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1", http_proxy=closed, https_proxy=closed,
               HTTP_PROXY=closed, HTTPS_PROXY=closed, no_proxy="", NO_PROXY="")
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                          str(ROOT / "mkdocs.yml"), "--site-dir", str(out)],
                         capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    return out


def built(site: Path, src: str) -> Path:
    """The HTML file the page `src` (relative to docs/) is built into."""
    stem = src.removesuffix(".md")
    return site / ("index.html" if stem == "index" else f"{stem}/index.html")


def public_names() -> dict[str, object]:
    """Every public name `import prebo` offers: `__all__` and whatever else its __init__ binds."""
    names = {n: v for n, v in vars(prebo).items() if not n.startswith("_") and not inspect.ismodule(v)}
    return names | {n: getattr(prebo, n) for n in prebo.__all__}


def documented(ids) -> set[int]:
    """The objects (by id) that the heading ids, dotted paths such as prebo.optimise.optimise, name."""
    found = set()
    for path in ids:
        module, _, name = path.rpartition(".")
        if not module.startswith("prebo"):
            continue
        try:
            found.add(id(getattr(importlib.import_module(module), name)))
        except (ImportError, AttributeError):
            pass  # a member's heading, such as prebo.Basis.N
    return found


def test_the_site_builds_strictly_with_every_page_name_and_option(site):
    pages = sorted(p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md"))
    assert "tutorial.md" in pages and "reference/api.md" in pages, pages
    for src in pages + ["readme.md", "reference/cli.md"]:
        assert built(site, src).is_file(), src
    api = built(site, "reference/api.md").read_text()
    headings = re.findall(r'<h\d id="([^"]+)" class="doc doc-heading"', api)
    missing = [n for n, v in public_names().items() if id(v) not in documented(headings)]
    assert not missing, f"no heading on the API page for prebo.{', prebo.'.join(missing)}"
    cli = html.unescape(re.sub(r"<[^>]+>", "", built(site, "reference/cli.md").read_text()))
    (commands,) = [a for a in parser()._actions if a.dest == "command"]
    for name, sub in commands.choices.items():
        assert f"prebo {name}" in cli, name
        for action in sub._actions:
            for option in action.option_strings or [action.metavar or action.dest]:
                assert option in cli, (name, option)


PROBE = """<!doctype html><body><script>
async function probe(path) {
  const frame = document.createElement("iframe");
  frame.width = 1280; frame.height = 1000;
  const loaded = new Promise(done => frame.onload = done);
  frame.src = path; document.body.appendChild(frame); await loaded;
  const doc = frame.contentDocument, win = frame.contentWindow;
  return {
    url: win.location.href,
    headings: [...doc.querySelectorAll("article h1, article h2, article h3")].map(h => (
      {tag: h.tagName, id: h.id, text: h.textContent.replace("¶", "").trim(),
       height: h.getBoundingClientRect().height})),
    images: [...doc.querySelectorAll("article img")].map(i => ({src: i.src, width: i.naturalWidth})),
    links: [...doc.querySelectorAll("a[href]")].map(a => a.href),
    ids: [...doc.querySelectorAll("[id]")].map(e => e.id),
    resources: win.performance.getEntriesByType("resource").map(e => e.name),
  };
}
(async () => {
  const report = {};
  for (const path of PATHS) report[path] = await probe(path);
  const pre = document.createElement("pre");
  pre.id = "report"; pre.textContent = JSON.stringify(report);
  document.body.appendChild(pre);
})();
</script></body>"""


class Site(http.server.SimpleHTTPRequestHandler):
    """The built site, and at /probe.html a page that loads PAGES in turn and reports what rendered."""

    def do_GET(self):
        if self.path != "/probe.html":
            return super().do_GET()
        body = PROBE.replace("PATHS", json.dumps(["/" + p for p in PAGES.values()])).encode()
        self.send_response(200)
        self.send_header("Content-Type", "text/html; charset=utf-8")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


def markdown_headings(src: str) -> list[str]:
    """The # and ## headings of docs/`src`, code blocks left out."""
    text = re.sub(r"^```.*?^```", "", (ROOT / "docs" / src).read_text(), flags=re.S | re.M)
    return re.findall(r"^##? (.+)$", text, re.M)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (apt-get install chromium; .ci/run installs it)")
def test_the_site_renders_in_chromium(site, tmp_path):
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Site, directory=str(site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    origin = f"http://127.0.0.1:{server.server_port}"
    try:
        dom = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                              f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=20000",
                              "--dump-dom", f"{origin}/probe.html"],
                             capture_output=True, text=True, timeout=120).stdout
    finally:
        server.shutdown()
        server.server_close()
    found = re.search(r'<pre id="report">(.*?)</pre>', dom, re.S)
    assert found, f"the probe reported nothing: {dom[-2000:]!r}"
    report = json.loads(html.unescape(found[1]))
    for src, path in PAGES.items():
        page = report["/" + path]
        rendered = [h for h in page["headings"] if h["height"] > 0]
        expected = markdown_headings(src)
        shown = [h["text"] for h in rendered if h["tag"] in ("H1", "H2")]
        assert shown == expected, (src, shown, expected)
        for link in page["links"]:
            url = urlsplit(link)
            if f"{url.scheme}://{url.netloc}" != origin:
                continue
            file = site / unquote(url.path).lstrip("/")
            assert (file / "index.html" if file.is_dir() else file).is_file(), (src, link)
            if url.fragment and url.path == urlsplit(page["url"]).path:
                assert unquote(url.fragment) in page["ids"], (src, link)
        assert all(r.startswith(origin + "/") for r in page["resources"]), (src, page["resources"])
    (picture,) = report["/tutorial/"]["images"]
    assert picture["src"].endswith("h2plus_ladder_densities.png") and picture["width"] > 0, picture
    headings = {h["id"] for h in report["/reference/api/"]["headings"] if h["height"] > 0}
    missing = [n for n, v in public_names().items() if id(v) not in documented(headings)]
    assert not missing, f"the API page shows no heading for prebo.{', prebo.'.join(missing)}"
