"""Sphinx configuration of the weakgrid documentation (``sphinx-build -W -b html docs docs/_build/html``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))          # document the source tree beside this folder
# the tutorials' kernels import the same tree
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(ROOT / "src")] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])

import weakgrid  # noqa: E402

project = "weakgrid"
author = "the weakgrid developers"
copyright = "the weakgrid developers, MIT licence"
release = weakgrid.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",            # MyST markdown pages and executed MyST text notebooks (includes myst_parser)
    "sphinxarg.ext",      # the CLI reference from weakgrid.cli.main.build_parser()
    "sphinx-mathjax-offline",  # MathJax served from _static: the pages need no network
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb"}
exclude_patterns = ["_build", "**.ipynb_checkpoints", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]
root_doc = "index"
# CLI help and docstrings are plain text: `--list` stays two hyphens (no en dash) and `x` is code
smartquotes_action = "qe"
default_role = "literal"

# ---- API reference: one page per public module, from the docstrings (numpydoc)
import types  # noqa: E402

import sphinx.ext.autosummary as _autosummary  # noqa: E402

_import_by_name = _autosummary._import_by_name


def _prefer_module(name, grouped_exception=True):
    """Resolve ``pkg.mod`` to the module even when ``pkg`` re-exports a function called ``mod``
    (``weakgrid.design.modes``, ``weakgrid.game.rollout``); autosummary would document the
    function under the module's name and lose the module's page."""
    found = _import_by_name(name, grouped_exception)
    mod = sys.modules.get(name)
    if isinstance(mod, types.ModuleType) and found[0] is not mod:
        return mod, None, name
    return found


_autosummary._import_by_name = _prefer_module
autosummary_generate = True
autosummary_ignore_module_all = True    # modules are found by walking the package
autodoc_default_options = {"members": True, "show-inheritance": True, "member-order": "bysource"}
autodoc_typehints = "none"                 # the numpydoc sections state types and units
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# ---- tutorials: MyST text notebooks executed at every build; an error fails the build
nb_execution_mode = "cache"                # a fresh clone (CI) executes every notebook
nb_execution_cache_path = str(Path(__file__).parent / "_build" / ".jupyter_cache")
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
myst_dmath_double_inline = True

# ---- HTML
html_theme = "pydata_sphinx_theme"
html_title = f"weakgrid {release}"
html_static_path = ["_static"]
html_css_files = ["weakgrid.css"]
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "header_links_before_dropdown": 7,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {p: [] for p in ("index", "theory", "findings", "beyond", "simulator", "cli",
                                  "tutorials/*")}
html_show_sourcelink = False
