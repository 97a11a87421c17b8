"""The user guide works as written: every ```python block of README.md and docs/*.md runs
(the blocks of a page in order, in one namespace), and every `planardyn ...` line of their
```bash blocks runs with exit status 0, interleaved in page order, in an empty folder where
`examples/` is the repository's. `planardyn demo` is left to test_demo (it takes seconds).
The site builds with `mkdocs build --strict` when mkdocs is installed.

Every figure a page shows as printed is the one the code prints: a ```text (or untagged)
block right after a ```python or ```bash block (nothing but blank lines between) is that
block's output, and must equal what the block prints, line by line (trailing spaces aside; a
line "..." stands for any number of lines). The minimum Rust the pages name is Cargo.toml's.
"""

from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
import sys
import textwrap

import pytest
from conftest import ROOT
from wheel_smoke import snippets

DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]

PRELUDE = textwrap.dedent(
    """
    import shlex, subprocess, sys
    import matplotlib
    matplotlib.use("Agg")

    def _planardyn(line):
        p = subprocess.run([sys.executable, "-m", "planardyn", *shlex.split(line)[1:]],
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, f"{line!r} exited {p.returncode}: {p.stderr}"
        print(p.stdout, end="")

    def _example(line):
        p = subprocess.run([sys.executable, *shlex.split(line)[1:]], capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, f"{line!r} exited {p.returncode}: {p.stderr}"
        print(p.stdout, end="")
    """
)


#: Any fenced block, its language (empty when untagged) and its text.
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)

#: Printed before each block's code in the page script, so that its output can be cut out.
SENTINEL = "\x1e--- block {} ---"


def page_script(page) -> tuple[str, int]:
    """The page as one Python script, and the number of blocks and commands in it."""
    code = snippets(page.read_text())
    parts = [PRELUDE] + [text if kind == "python" else f"_planardyn({text!r})" for kind, text in code]
    return "\n".join(parts), len(code)


def page_blocks(markdown: str) -> list[tuple[list[tuple[str, str]], str | None]]:
    """The code blocks that run, in page order, each as its code (snippets' python blocks
    and planardyn commands) and the ```text block right after it (None without one). A bash
    block of `python examples/...` lines runs them only when its output is shown."""
    return [(code, None if shown is None else shown.group(2)) for code, shown in page_block_matches(markdown)]


def page_block_matches(markdown: str) -> list[tuple[list[tuple[str, str]], re.Match[str] | None]]:
    """page_blocks with each shown ```text block as its FENCE match (where it is on the page:
    tools/update_docs_outputs.py rewrites it there)."""
    found = list(FENCE.finditer(markdown))
    out = []
    for i, m in enumerate(found):
        nxt = found[i + 1] if i + 1 < len(found) else None
        shown = (nxt if nxt is not None and nxt.group(1) in ("text", "")
                 and not markdown[m.end():nxt.start()].strip() else None)
        code = snippets(m.group(0))
        if not code and m.group(1) == "bash" and shown is not None:
            code = [("example", line.strip()) for line in m.group(2).splitlines() if line.startswith("python examples/")]
        if code:
            out.append((code, shown))
    return out


def expected_outputs(markdown: str) -> dict[int, str]:
    """{k: text} for the running blocks (page_blocks, from 0) that a ```text block follows."""
    return {k: shown for k, (_, shown) in enumerate(page_blocks(markdown)) if shown is not None}


def checked_script(page) -> tuple[str, int]:
    """The page script with a sentinel printed before every running block's code (SENTINEL
    with the block's number)."""
    call = {"planardyn": "_planardyn", "example": "_example"}
    parts = [PRELUDE]
    blocks = page_blocks(page.read_text())
    for k, (code, _) in enumerate(blocks):
        parts.append(f"print({SENTINEL.format(k)!r})")
        parts += [text if kind == "python" else f"{call[kind]}({text!r})" for kind, text in code]
    return "\n".join(parts), len(blocks)


def run_page(page, folder) -> dict[int, str]:
    """Runs checked_script in ``folder`` (empty, but for a link to examples/): {k: what
    running block k printed}."""
    script, n = checked_script(page)
    (folder / "examples").symlink_to(ROOT / "examples")
    (folder / "page.py").write_text(script)
    p = subprocess.run([sys.executable, "page.py"], cwd=folder, capture_output=True, text=True, timeout=600,
                       env={**__import__("os").environ, "MPLBACKEND": "Agg"})
    assert p.returncode == 0, f"{page.name}:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    return dict(zip(range(n), re.split(r"\x1e--- block \d+ ---\n", p.stdout)[1:]))


def matches(got: str, want: str) -> bool:
    """Line by line, trailing spaces aside; a line "..." in ``want`` stands for any lines."""
    pattern = "\n".join(".*?" if line.strip() == "..." else re.escape(line.rstrip()) for line in want.strip("\n").splitlines())
    text = "\n".join(line.rstrip() for line in got.strip("\n").splitlines())
    return re.fullmatch(pattern, text, re.S) is not None


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_page_code_runs(page, tmp_path):
    if checked_script(page)[1] == 0:
        pytest.skip(f"{page.name} has no Python block or planardyn command")
    printed = run_page(page, tmp_path)
    wrong = [f"block {k}: the page shows\n{want}\nthe code prints\n{printed.get(k, '')}"
             for k, want in expected_outputs(page.read_text()).items() if not matches(printed.get(k, ""), want)]
    assert not wrong, f"{page.name}: " + "\n".join(wrong)


def test_the_pages_name_the_minimum_rust_cargo_asks_for():
    # Issue 23: the README said 1.86, docs/index.md 1.85; Cargo.toml's rust-version decides.
    want = re.search(r'^rust-version = "([\d.]+)"', (ROOT / "Cargo.toml").read_text(), re.M)
    assert want is not None
    named = {page.name: re.findall(r"Rust \(([\d.]+)\+\)", page.read_text()) for page in PAGES}
    assert named["README.md"] and named["index.md"]
    assert {v for vs in named.values() for v in vs} == {want.group(1)}, named


def test_pages_have_the_promised_code():
    # What a new user follows: describe a five-bar, simulate it, view it, plot torques, invert.
    examples, _ = page_script(DOCS / "examples.md")
    for needle in ("pdy.load(\"my-five-bar.yaml\")", "mech.simulate(", "animate(mech, res, \"fall.html\")",
                   "plot_efforts(inv", "inverse_result(mech, t, q)"):
        assert needle in examples, needle
    cli, n = page_script(DOCS / "cli.md")
    for cmd in ("check", "simulate", "plot", "animate", "inverse"):
        assert f"_planardyn('planardyn {cmd} " in cli, cmd
    assert n >= 10


def test_mkdocs_build_strict(tmp_path):
    # --strict: every link checked, those to files of the repository too (docs_hooks/
    # repository_files.py puts them in the site; issue 26: they were dead on the site).
    pytest.importorskip("mkdocs")
    pytest.importorskip("pymdownx")
    p = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    site = tmp_path / "site"
    for page in ("index.html", "cli/index.html", "api/index.html", "examples/index.html", "model-format/index.html",
                 "benchmarks/index.html", "repo/schema/planardyn-model.schema.json",
                 "repo/examples/models/library/four-bar.yaml"):
        assert (site / page).is_file(), page
    assert "planardyn inverse" in (site / "cli" / "index.html").read_text()
    home = (site / "index.html").read_text()
    assert 'href="benchmarks/"' in home  # in the navigation (issue 26)
    assert 'href="../repo/examples/models/library/four-bar.yaml"' in (site / "library" / "index.html").read_text()
    # The formulas: KaTeX from the site itself, no CDN; every one parses.
    assert (site / "assets" / "katex" / "katex.min.js").is_file() and (site / "assets" / "katex" / "LICENSE").is_file()
    assert list((site / "assets" / "katex" / "fonts").glob("*.woff2"))
    pages = [f.read_text() for f in site.rglob("*.html")]
    assert not [m for text in pages for m in re.findall(r'(?:src|href)="(https?://[^"]*)"', text)
                if re.search(r"\.(js|css)\b", m)]
    formulation = (site / "formulation" / "index.html").read_text()
    formulas = [html.unescape(f).strip() for f in
                re.findall(r'<(?:span|div) class="arithmatex">(.*?)</(?:span|div)>', formulation, re.S)]
    assert len(formulas) >= 50 and "katex.min.js" in formulation
    assert_katex_parses(formulas)


def assert_katex_parses(formulas: list[str]) -> None:
    """Each \\(...\\) or \\[...\\] formula through KaTeX (node, the npm package the site ships)."""
    node = shutil.which("node")
    katex = ROOT / "node_modules" / "katex"
    if node is None or not katex.is_dir():
        pytest.skip("node or node_modules/katex missing")
    script = ("const k=require(process.argv[1]);let bad=[];"
              "for(const t of JSON.parse(require('fs').readFileSync(0,'utf8'))){"
              "try{k.renderToString(t.slice(2,-2),{displayMode:t.startsWith('\\\\['),throwOnError:true})}"
              "catch(e){bad.push(t+': '+e.message)}}console.log(JSON.stringify(bad))")
    p = subprocess.run([node, "-e", script, str(katex)], input=json.dumps(formulas), capture_output=True, text=True,
                       timeout=60)
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout) == []


#: The alias the pages, examples and docstrings use for planardyn (issue 26, first hour 2):
#: `pd` is pandas' by convention, and a page using both could not tell them apart.
ALIAS = "pdy"


def test_planardyn_is_never_imported_as_pandas_alias():
    texts = [*PAGES, *sorted((ROOT / "examples").glob("*.py")), *sorted((ROOT / "python" / "planardyn").rglob("*.py")),
             ROOT / "tests" / "wheel_smoke.py"]
    clash = re.compile(r"import planardyn as pd\b|\bpd\.(load|load_example|from_result|read_results|models)\b")
    found = [f"{p.relative_to(ROOT)}:{n}: {line.strip()}" for p in texts
             for n, line in enumerate(p.read_text().splitlines(), 1) if clash.search(line)]
    assert not found, "\n".join(found)
    # One alias everywhere, and the README, the home page and the API page use it.
    aliases = {a for p in texts for a in re.findall(r"import planardyn as (\w+)", p.read_text())}
    assert aliases == {ALIAS}, aliases
    assert all(f"import planardyn as {ALIAS}\n" in (DOCS / name).read_text() for name in ("index.md", "api.md"))
    assert f"import planardyn as {ALIAS}\n" in (ROOT / "README.md").read_text()
