"""mkdocs hook: the pages' links to files of the repository outside docs/ (the model files,
the JSON Schema, the benchmark figures: ``](../examples/models/five-bar.yaml)``) work on the
built site too. Each such file is added to the site under ``repo/`` (its path in the
repository kept) and the links are pointed there, so ``mkdocs build --strict`` checks them
like any other: a link to a file that does not exist fails the build. On GitHub the links are
the repository's own and work as written.
"""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[1]
#: A Markdown link or image to a path that leaves docs/: ](../path) or ](../path#anchor).
LINK = re.compile(r"\]\(\.\./([^)#\s]+)(#[^)\s]*)?\)")
#: Where the repository's files go in the site.
PREFIX = "repo"


def _targets(docs_dir: Path) -> set[str]:
    """Every repository file a page links to, as its path from the repository's root."""
    found = set()
    for page in docs_dir.glob("*.md"):
        for match in LINK.finditer(page.read_text(encoding="utf-8")):
            if (ROOT / match.group(1)).is_file():
                found.add(match.group(1))
    return found


def on_files(files, config, **kwargs):
    for path in sorted(_targets(Path(config["docs_dir"]))):
        files.append(File.generated(config, f"{PREFIX}/{path}", abs_src_path=str(ROOT / path)))
    return files


def on_page_markdown(markdown, page, config, files, **kwargs):
    # Pages sit at the top of docs/: ../path in the repository is repo/path in the site. A link
    # to a folder or a missing file is left as it is, for the link check to report.
    def point(match: re.Match[str]) -> str:
        path, anchor = match.group(1), match.group(2) or ""
        return f"]({PREFIX}/{path}{anchor})" if (ROOT / path).is_file() else match.group(0)

    return LINK.sub(point, markdown)
