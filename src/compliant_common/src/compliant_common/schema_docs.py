"""The parameter tables of the package READMEs, generated from the schemas (:mod:`compliant_common.schema`).

A README marks each generated table with the schema it shows (``module:ATTRIBUTE``) and an optional key
prefix::

    <!-- params:begin keyboard_publisher.teleop:PARAMETERS prefix=~ -->
    (generated: do not edit, run the command below)
    <!-- params:end -->

``python -m compliant_common.schema_docs --write`` (``make param-tables``) rewrites every table under
``src/*/README.md``; without ``--write`` it only lists the READMEs whose tables are out of date (exit 1).
tests/test_param_tables.py runs the check.
"""

from __future__ import annotations

import argparse
import importlib
import pathlib
import re
import sys
from collections.abc import Sequence

from compliant_common.schema import Schema

__all__ = ["MARKER", "NOTE", "load_schema", "main", "render", "stale_readmes"]

MARKER = re.compile(
    r"(?P<begin><!-- params:begin (?P<source>[\w.]+:\w+)(?: prefix=(?P<prefix>\S+))? -->\n)"
    r"(?P<body>.*?)"
    r"(?P<end><!-- params:end -->)",
    re.S,
)

NOTE = "<!-- generated from the declarations: edit those, then `make param-tables` -->\n"

# The source tree when run from a devel space or the source checkout: src/<pkg>/src/compliant_common/here.
_SRC = pathlib.Path(__file__).resolve().parents[3]


def load_schema(source: str) -> Schema:
    """The schema named "module:ATTRIBUTE".

    Raises:
        ValueError: The attribute is not a Schema.
    """
    module, _, attribute = source.partition(":")
    schema = getattr(importlib.import_module(module), attribute)
    if not isinstance(schema, Schema):
        raise ValueError(f"{source} is a {type(schema).__name__}, not a compliant_common.schema.Schema")
    return schema


def render(text: str) -> str:
    """The README text with every marked table regenerated."""

    def table(match: re.Match[str]) -> str:
        body = NOTE + load_schema(match["source"]).table(prefix=match["prefix"] or "")
        return f"{match['begin']}{body}{match['end']}"

    return MARKER.sub(table, text)


def stale_readmes(src: pathlib.Path = _SRC) -> list[pathlib.Path]:
    """The READMEs under `src`/*/ whose generated tables differ from the schemas."""
    return [path for path in sorted(src.glob("*/README.md")) if render(text := path.read_text()) != text]


def main(argv: Sequence[str] | None = None) -> int:
    """Checks (exit 1 naming the stale READMEs) or, with --write, rewrites the tables."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--write", action="store_true", help="rewrite the stale tables")
    parser.add_argument(
        "--src", type=pathlib.Path, default=_SRC, help="the catkin source space (default: %(default)s)"
    )
    args = parser.parse_args(argv)
    stale = stale_readmes(args.src)
    for path in stale:
        if args.write:
            path.write_text(render(path.read_text()))
            print(f"rewrote the parameter table(s) of {path}")
        else:
            print(f"{path}: parameter table out of date")
    if stale and not args.write:
        print("run: scripts/with_env python -m compliant_common.schema_docs --write", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
