"""``balpipe schema``: print the JSON Schema of a spec (:func:`balpipe.loader.schema`)."""

from __future__ import annotations

import json

from .common import emit


def add_parser(sub) -> None:
    s = sub.add_parser("schema", help="print the JSON Schema of a spec", description="Print the spec JSON Schema.")
    s.add_argument("-o", "--out", metavar="FILE", help="write to FILE instead of stdout")


def run(args) -> int:
    from ..loader import schema

    return emit(json.dumps(schema(), indent=2, sort_keys=True) + "\n", args.out)
