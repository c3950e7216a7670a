"""Sphinx configuration of the pendulum-fmu docs site.

Built by the one command the README names (from the repository root):

    .venv/bin/sphinx-build -W -b html docs docs/_build/html

``-W`` turns every warning into an error, as CI (.ci/run) builds it. The pages are the Markdown
files of this folder (MyST), the API reference comes from the numpydoc docstrings (autodoc,
autosummary), the command line from the parser (sphinx-argparse), and the examples page from
running examples/*.py during the build (_ext/example_pages.py), and the wasm page's scripts
from the FMU's wasm binary (_ext/wasm_page.py: Node 20 needed; on a fresh clone it runs
`npm ci --prefix web` itself, from the npm registry).
"""

import importlib
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
# The checkout's package is documented, whatever is installed; _ext holds this site's extension.
sys.path[:0] = [str(ROOT), str(DOCS / "_ext")]

project = "pendulum-fmu"
author = "the pendulum-fmu developers"
copyright = f"2026, {author}"
release = version = importlib.import_module("pendulum_fmu").__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinxarg.ext",
    "example_pages",
    "wasm_page",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# random_steps.csv and the like are data the pages link to, not pages.
exclude_patterns = ["_build", "_ext", "examples_intro.md"]

# Headings ## and ### get anchors, so that [text](page.md#a-heading) links resolve.
myst_heading_anchors = 3
myst_enable_extensions = ["colon_fence"]

autosummary_generate = True
autodoc_typehints = "none"  # the numpydoc Parameters section says the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# numpydoc's own checks of the docstrings' sections, as warnings (errors under -W).
numpydoc_validation_checks = {"GL08"}  # every documented object has a docstring
# ... but a class's __init__ (a dataclass's made by Python): its class's docstring describes it,
# as ruff's D107 ignore says.
numpydoc_validation_exclude = {r"\.__init__$"}

html_theme = "pydata_sphinx_theme"
html_title = f"pendulum-fmu {release}"
html_static_path = []
templates_path = ["_templates"]
html_theme_options = {
    "navigation_with_keys": False,
    # The sidebar lists every page (below): the header's links to the same pages would repeat it.
    "navbar_center": [],
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
# Every page, by index.md's captions (_templates/sidebar-site-nav.html): the theme's section
# navigation is empty on a site whose pages are all top-level.
html_sidebars = {"**": ["sidebar-site-nav"]}

# The parser's help texts are plain text that sphinx-argparse reads as reStructuredText, where
# |dtheta| would be a substitution: each stands for itself.
rst_prolog = "\n".join(rf".. |{name}| replace:: \|{name}\|" for name in ("dtheta", "domega"))
