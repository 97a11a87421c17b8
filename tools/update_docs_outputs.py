"""Rewrites the printed outputs the docs pages show with what their code prints now.

Runs each page as tests/test_docs.py does (its page script, in an empty folder with a link to
examples/) and replaces each ```text block that no longer matches its code's output (by
test_docs.matches) with that output, in place. A block's "..." lines are kept: each run of
lines between them takes as many printed lines (the first run from the start, the last from
the end, the others where the printed lines are most alike); where that does not fit, the
block becomes the whole output. Prints a unified diff of each page it changes.

    .venv/bin/python tools/update_docs_outputs.py                  # README.md and docs/*.md
    .venv/bin/python tools/update_docs_outputs.py --page docs/api.md --page docs/robot.md
    .venv/bin/python tools/update_docs_outputs.py --dry-run        # the diff only

Read each change before committing it: the tool makes the pages agree with the code, not
right.
"""

from __future__ import annotations

import argparse
import difflib
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import test_docs  # noqa: E402  (tests/ on the path first)

ELLIPSIS = "..."


def elided(got: str, want: str) -> str:
    """``got`` (the printed lines) with ``want``'s "..." lines kept where it has them."""
    lines = [line.rstrip() for line in got.strip("\n").splitlines()]
    full = "\n".join(lines) + "\n"
    runs: list[list[str]] = [[]]
    for line in want.strip("\n").splitlines():
        if line.strip() == ELLIPSIS:
            runs.append([])
        else:
            runs[-1].append(line.rstrip())
    if len(runs) == 1 or sum(map(len, runs)) > len(lines):
        return full
    head, *middle, tail = runs
    start, end = len(head), len(lines) - len(tail)
    out = lines[:start]
    for run in middle:
        out.append(ELLIPSIS)
        if run:
            best = max(range(start, end - len(run) + 1), default=None,
                       key=lambda i: difflib.SequenceMatcher(None, "\n".join(run), "\n".join(lines[i:i + len(run)])).ratio())
            if best is None:
                return full
            out += lines[best:best + len(run)]
            start = best + len(run)
    out += [ELLIPSIS, *lines[end:]]
    text = "\n".join(out) + "\n"
    return text if test_docs.matches(got, text) else full


def updated(page: Path) -> str:
    """The page's text with its stale printed outputs rewritten."""
    markdown = page.read_text()
    with tempfile.TemporaryDirectory() as folder:
        printed = test_docs.run_page(page, Path(folder))
    shown = [(k, m) for k, (_, m) in enumerate(test_docs.page_block_matches(markdown)) if m is not None]
    for k, m in reversed(shown):
        got = printed.get(k, "")
        if not test_docs.matches(got, m.group(2)):
            markdown = markdown[:m.start(2)] + elided(got, m.group(2)) + markdown[m.end(2):]
    return markdown


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--page", action="append", type=Path,
                        help="a page to update (repeatable); default README.md and docs/*.md")
    parser.add_argument("--dry-run", action="store_true", help="print the diff, leave the pages")
    args = parser.parse_args()
    pages = [p.resolve() for p in args.page] if args.page else test_docs.PAGES
    changed = 0
    for page in pages:
        before = page.read_text()
        after = updated(page)
        if after == before:
            continue
        changed += 1
        name = str(page.relative_to(test_docs.ROOT))
        sys.stdout.writelines(difflib.unified_diff(before.splitlines(True), after.splitlines(True), name, name))
        if not args.dry_run:
            page.write_text(after)
    print(f"{changed} of {len(pages)} pages {'would change' if args.dry_run else 'changed'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
