"""mkdocs hook: the formulas of the site rendered by KaTeX, served from the site itself.

pymdownx.arithmatex (mkdocs.yml) leaves each formula, written in LaTeX between $...$ or $$...$$,
in an element of class ``arithmatex``; docs/assets/katex-init.js renders them with KaTeX. KaTeX
comes from npm (package.json, package-lock.json at the repository's root): this hook runs
``npm ci`` when node_modules/ lacks it, and copies its script, style sheet, fonts and licence into
the built site's assets/katex/, so the site works offline and asks no CDN.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from mkdocs.exceptions import PluginError

ROOT = Path(__file__).resolve().parents[1]
DIST = ROOT / "node_modules" / "katex" / "dist"
#: What the site needs of KaTeX's dist/ (the fonts: woff2, which every current browser reads).
FILES = ("katex.min.js", "katex.min.css")


def on_pre_build(config, **kwargs) -> None:
    if (DIST / FILES[0]).is_file():
        return
    npm = shutil.which("npm")
    if npm is None:
        raise PluginError("the docs need KaTeX from npm: install Node.js and npm, then run `npm ci` in "
                          f"{ROOT} (package-lock.json)")
    done = subprocess.run([npm, "ci", "--no-audit", "--no-fund", "--loglevel=error"], cwd=ROOT,
                          capture_output=True, text=True)
    if done.returncode != 0 or not (DIST / FILES[0]).is_file():
        raise PluginError(f"`npm ci` in {ROOT} did not install KaTeX:\n{done.stderr[-2000:]}")


def on_post_build(config, **kwargs) -> None:
    out = Path(config["site_dir"]) / "assets" / "katex"
    (out / "fonts").mkdir(parents=True, exist_ok=True)
    for name in FILES:
        shutil.copy2(DIST / name, out / name)
    for font in (DIST / "fonts").glob("*.woff2"):
        shutil.copy2(font, out / "fonts" / font.name)
    shutil.copy2(DIST.parent / "LICENSE", out / "LICENSE")
