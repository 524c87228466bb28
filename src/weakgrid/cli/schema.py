"""``weakgrid schema``: the study file's JSON Schema, or its reference page, to a file or stdout."""

from __future__ import annotations

import sys

from ._common import HelpFormatter, output_file

NAME = "schema"


def add_parser(sub):
    """Add ``weakgrid schema`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="the study file's JSON Schema (or its reference page)",
        description="Write the JSON Schema of a study file (for an editor that checks TOML "
                    "against a schema, e.g. Taplo: first line `#:schema ./study.schema.json`), "
                    "or with --markdown the study-file reference page (docs/study-file-"
                    "reference.md). Both are rendered from the field declarations the "
                    "validator uses (weakgrid.study.fields); the package ships the schema as "
                    "weakgrid/data/study.schema.json.",
        formatter_class=HelpFormatter)
    p.add_argument("--markdown", action="store_true", help="the reference page instead")
    p.add_argument("--output", "-o", type=output_file(".json", ".md"), default=None,
                   help="file to write (default: standard output)")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid schema`` with the parsed ``args``; return the exit status."""
    from ..fileio import write_text_atomic
    from ..study.reference import reference_markdown, schema_text

    text = reference_markdown() if args.markdown else schema_text()
    if args.output is None:
        sys.stdout.write(text)
    else:
        print(f"wrote {write_text_atomic(args.output, text)}")
    return 0
