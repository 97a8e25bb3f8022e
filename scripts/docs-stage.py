#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Puts the documentation site's pages together for Sphinx (make docs):
    scripts/docs-stage.py OUT
docs/site/ (configuration, index, API page), docs/*.md and their figures, the README, the style pages
(lammps-pkg/SEDIMENT/doc/*.rst under styles/) and the notebook as a tutorial page. A link to a file
of the repository that is not a page of the site becomes the file's name in code."""
from __future__ import annotations

import json
import re
import shutil
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")


def relink(text: str, folder: str) -> str:
    """Markdown links: pages and figures of the site stay links; other repository files become names."""
    def one(match: re.Match) -> str:
        image, label, target = match.groups()
        if target.startswith(("http://", "https://", "#")):
            return match.group(0)
        path, _, anchor = target.partition("#")
        site = (REPO / folder / path).resolve()
        if site.is_relative_to(REPO / "docs") and site.exists():
            return f"{image}[{label}]({site.relative_to(REPO / 'docs')}{'#' + anchor if anchor else ''})"
        return f"{label} (`{site.relative_to(REPO) if site.is_relative_to(REPO) else path}`)"
    return LINK.sub(one, text)


def notebook_page(path: Path) -> str:
    """A notebook as a page: its markdown cells, and its code cells as Python blocks."""
    cells = json.loads(path.read_text())["cells"]
    parts = []
    for cell in cells:
        source = "".join(cell["source"])
        parts.append(relink(source, "notebooks") if cell["cell_type"] == "markdown" else f"```python\n{source}\n```")
    return "\n\n".join(parts) + "\n"


def main() -> None:
    out = Path(sys.argv[1])
    shutil.rmtree(out, ignore_errors=True)
    shutil.copytree(REPO / "docs", out, ignore=shutil.ignore_patterns("site"))
    for page in out.glob("*.md"):
        page.write_text(relink(page.read_text(), "docs"))
    for name in ("conf.py", "index.rst", "api.rst"):
        shutil.copy(REPO / "docs" / "site" / name, out / name)
    (out / "README.md").write_text(relink((REPO / "README.md").read_text(), "."))
    (out / "styles").mkdir()
    for page in (REPO / "lammps-pkg" / "SEDIMENT" / "doc").glob("*.rst"):
        shutil.copy(page, out / "styles" / page.name)
    (out / "tutorial.md").write_text(notebook_page(REPO / "notebooks" / "sedimentation_test.ipynb"))


if __name__ == "__main__":
    main()
