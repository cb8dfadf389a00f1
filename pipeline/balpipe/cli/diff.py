"""``balpipe diff OLD NEW``: compare two designs, inputs and results (:mod:`balpipe.diff`)."""

from __future__ import annotations

import sys

from .common import EXIT_USAGE, emit


def add_parser(sub) -> None:
    d = sub.add_parser("diff", help="compare two designs: inputs and results",
                       description="Compare two specs (files, or REV:PATH for a spec at a git revision): "
                       "what changed in the inputs and what it did to the parameters, peaks, added mass, "
                       "references and validation residuals.")
    d.add_argument("old", metavar="OLD", help="spec file or REV:PATH, e.g. HEAD~1:specs/a.yaml")
    d.add_argument("new", metavar="NEW", help="spec file or REV:PATH")
    d.add_argument("-f", "--format", choices=["text", "markdown", "json", "html"], default="text",
                   help="output format (default: text)")
    d.add_argument("-o", "--out", metavar="FILE", help="write to FILE instead of stdout")
    d.add_argument("--no-sim", action="store_true", help="skip the pymunk validation of both designs")
    d.add_argument("--site", metavar="URL", default="",
                   help="HTML: the report site's index to link back to (default: an index.html beside or above -o)")


def run(args) -> int:
    from .. import diff
    from ..loader import SpecErrors

    try:
        a = diff.run_side(args.old, simulate=not args.no_sim)
        b = diff.run_side(args.new, simulate=not args.no_sim)
    except SpecErrors as exc:
        print(str(exc), file=sys.stderr)
        return EXIT_USAGE
    data = diff.compare(a, b)
    text = (diff.to_html(data, a, b, site=diff.site_link(args.site, args.out), out=args.out) if args.format == "html"
            else diff.RENDERERS[args.format](data))
    return emit(text, args.out)
