# SPDX-License-Identifier: GPL-2.0-or-later
"""Sphinx configuration of the SEDIMENT documentation site (`make docs`; scripts/docs-stage.py puts
the pages together in build/docs-src first)."""
import os
import sys
from pathlib import Path

sys.path.insert(0, os.environ["SEDIMENT_PYTHON"])    # the checkout's python/, built (make docs sets it)

project = "SEDIMENT"
author = "the SEDIMENT developers"
copyright = "the SEDIMENT developers, GPL-2.0-or-later"
from sediment import _core    # noqa: E402  (the release, from the core: core/include/sediment/version.hpp)

release = version = _core.VERSION
extensions = ["myst_parser", "sphinx.ext.autodoc", "numpydoc", "sphinx.ext.mathjax"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
master_doc = "index"
html_theme = "alabaster"
html_theme_options = {"description": "Fluid forces for DEM spheres in LAMMPS, and sedimentation-test readouts"}
myst_heading_anchors = 3
numpydoc_show_class_members = False
autodoc_member_order = "bysource"
nitpicky = False


def lammps_reference(app, env, node, contnode):
    """A :doc: to a LAMMPS page that this site does not have (run, read_restart, ...): LAMMPS's own."""
    from docutils import nodes

    import difflib

    if node.get("refdomain") == "std" and node.get("reftype") == "doc":
        target = node["reftarget"].split("/")[-1]
        ours = [Path(name).name for name in env.found_docs if name.startswith("styles/")]
        # A typo of one of this site's pages stays an error; LAMMPS's fix_nve_sphere (a prefix of
        # this site's fix_nve_sphere_fluid) is LAMMPS's.
        if any(not page.startswith(target) for page in difflib.get_close_matches(target, ours, cutoff=0.8)):
            return None
        reference = nodes.reference("", "", internal=False, refuri=f"https://docs.lammps.org/{target}.html")
        reference.append(contnode)
        return reference
    return None


def setup(app):
    from pygments.lexers.shell import BashLexer

    for name in ("LAMMPS", "lammps"):    # LAMMPS input: commands and # comments, as a shell reads
        app.add_lexer(name, BashLexer)
    app.connect("missing-reference", lammps_reference)
