"""Every option's help says its default once, and never a default that says nothing."""

import argparse
import re

from weakgrid.cli.main import build_parser


def _option_helps():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, sp in sub.choices.items():
        fmt = sp._get_formatter()
        for a in sp._actions:
            if a.help and a.help is not argparse.SUPPRESS:
                yield name, a.dest, fmt._expand_help(a)


def test_no_default_said_twice_or_empty():
    helps = list(_option_helps())
    assert len(helps) > 80          # the whole CLI was seen
    twice = [(c, d) for c, d, h in helps if len(re.findall(r"default", h, re.I)) > 1]
    empty = [(c, d) for c, d, h in helps if re.search(r"\(default: (None|False)\)", h)]
    assert twice == [] and empty == []


def test_a_real_default_is_still_shown():
    helps = {(c, d): h for c, d, h in _option_helps()}
    assert "(default: c)" in helps[("export", "format")]
