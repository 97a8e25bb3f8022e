#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Puts the documentation site's pages together for Sphinx (make docs):
    scripts/docs-stage.py OUT
docs/site/ (configuration, index, API page), docs/*.md and their figures, the README, the style pages
(lammps-pkg/SEDIMENT/doc/*.rst under styles/) and the notebook as a tutorial page. A link to a file
of the repository that is not a page of the site becomes the file's name in code.

The tutorial shows the notebook as it runs here: it is executed (nbclient, the python3 kernel) with the
checkout's package (PYTHONPATH) and SEDIMENT_LMP as the environment gives them (make docs sets both),
its run in OUT-notebook/ beside OUT with the executed notebook, and its printed text and figures go
into the page. Nothing executed is committed: the repository keeps the notebook without outputs."""
from __future__ import annotations

import base64
import re
import shutil
import sys
import warnings
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


ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def execute_notebook(path: Path, run: Path) -> dict:
    """The notebook executed in `run` (its SEDIMENT_NOTEBOOK_OUT), which also gets the executed copy."""
    import os

    import nbformat
    from nbclient import NotebookClient

    shutil.rmtree(run, ignore_errors=True)
    run.mkdir(parents=True)
    from nbformat.warnings import MissingIDFieldWarning

    with warnings.catch_warnings():    # the checked-in notebook's cells carry no ids: given here, not in the file
        warnings.simplefilter("ignore", MissingIDFieldWarning)
        notebook = nbformat.read(path, as_version=4)
    os.environ["SEDIMENT_NOTEBOOK_OUT"] = str(run)
    os.environ["PYDEVD_DISABLE_FILE_VALIDATION"] = "1"    # the kernel's debugger note on frozen modules
    # no cell timeout: the run's length is the machine's business; a failing cell stops the build
    NotebookClient(notebook, timeout=None, kernel_name="python3", resources={"metadata": {"path": str(run)}}).execute()
    nbformat.write(notebook, run / path.name)
    return notebook


def fenced(text: str, language: str = "text") -> str:
    """A fenced block that no backtick run inside `text` can close."""
    fence = "`" * max(3, max((len(m) for m in re.findall(r"`+", text)), default=0) + 1)
    return f"{fence}{language}\n{text.rstrip()}\n{fence}"


def notebook_page(notebook: dict, figures: Path) -> str:
    """A notebook as a page: its markdown cells, its code cells as Python blocks, each followed by what
    it printed and the figures it drew (PNG files written into `figures`, beside the page)."""
    figures.mkdir(parents=True, exist_ok=True)
    parts = []
    for k, cell in enumerate(notebook["cells"]):
        source = "".join(cell["source"])
        if cell["cell_type"] == "markdown":
            parts.append(relink(source, "notebooks"))
            continue
        parts.append(fenced(source, "python"))
        for j, output in enumerate(cell.get("outputs", [])):
            kind, data = output["output_type"], output.get("data", {})
            if kind == "stream":
                parts.append(fenced(ANSI.sub("", "".join(output["text"]))))
            elif kind == "error":
                raise RuntimeError(f"notebook cell {k} failed: {output['ename']}: {output['evalue']}")
            elif "image/png" in data:
                name = f"cell{k:02d}-{j}.png"
                (figures / name).write_bytes(base64.b64decode(data["image/png"]))
                parts.append(f"![output of the cell above]({figures.name}/{name})")
            elif "text/plain" in data:
                parts.append(fenced(ANSI.sub("", "".join(data["text/plain"]))))
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
    notebook = execute_notebook(REPO / "notebooks" / "sedimentation_test.ipynb", out.parent / f"{out.name}-notebook")
    (out / "tutorial.md").write_text(notebook_page(notebook, out / "tutorial"))


if __name__ == "__main__":
    main()
