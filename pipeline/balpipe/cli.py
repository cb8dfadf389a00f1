"""The ``balpipe`` command line: build, check, diff, schema, sweep (:mod:`balpipe.cli_sweep`)."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from . import __version__

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143  # 128 + SIGINT, 128 + SIGTERM


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main process so that builds stop as cleanly as on Ctrl-C."""


def _on_sigterm(signum, frame) -> None:
    raise Terminated()


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # usage errors: exit 2, no traceback
        self.print_usage(sys.stderr)
        print(f"balpipe: error: {message}", file=sys.stderr)
        sys.exit(EXIT_USAGE)


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="balpipe", description="Dynamic balancing of planar mechanisms from YAML specs.")
    p.add_argument("--version", action="version", version=f"balpipe {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    b = sub.add_parser("build", help="build the report site from specs",
                       description="Compute, analyse, validate and report every spec; skip unchanged ones.")
    b.add_argument("paths", nargs="+", metavar="PATH", help="spec files or folders of specs")
    b.add_argument("-o", "--out", default="reports", metavar="DIR", help="output folder (default: reports)")
    b.add_argument("-j", "--jobs", type=int, default=1, metavar="N", help="build N specs in parallel")
    b.add_argument("--no-sim", action="store_true", help="skip the pymunk validation (quick iterations)")
    b.add_argument("--force", action="store_true", help="rebuild specs even when unchanged")
    b.add_argument("-q", "--quiet", action="store_true", help="print only errors and the summary")
    c = sub.add_parser("check", help="validate specs without building",
                       description="Check specs: schema, units, geometry and balancing feasibility.")
    c.add_argument("paths", nargs="+", metavar="PATH", help="spec files or folders of specs")
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
    s = sub.add_parser("schema", help="print the JSON Schema of a spec", description="Print the spec JSON Schema.")
    s.add_argument("-o", "--out", metavar="FILE", help="write to FILE instead of stdout")
    from .history_cli import add_parser as _add_history_parser

    _add_history_parser(sub)

    from .cli_sweep import add_parser as add_sweep

    add_sweep(sub)
    return p


def _missing(paths: list[str]) -> list[str]:
    return [p for p in paths if not Path(p).exists()]


def paths_jobs_problem(paths: list[str], jobs: int) -> str | None:
    """What is wrong with the spec paths and ``--jobs`` of a command that runs specs in parallel
    (``build``, ``history``): a usage error to print, or None."""
    missing = _missing(paths)
    if missing:
        return f"no such file or folder: {', '.join(missing)}"
    if jobs < 1:
        return "--jobs must be at least 1"
    return None


def cmd_build(args) -> int:
    from .build import Options, build

    problem = paths_jobs_problem(args.paths, args.jobs)
    if problem:
        print(f"balpipe: error: {problem}", file=sys.stderr)
        return EXIT_USAGE
    opts = Options(out=Path(args.out), simulate=not args.no_sim, force=args.force)

    def progress(k: int, total: int, o) -> None:
        if k == 0:  # refused before any work (unreadable folder, page name clash)
            print(o.message, file=sys.stderr)
            return
        if args.quiet and o.status in ("ok",):
            return
        tag = "unchanged" if o.skipped else o.status
        print(f"[{k}/{total}] {o.source}: {tag} ({o.seconds:.2f} s)", file=sys.stderr)
        if o.status != "ok" and o.message and not o.skipped:
            print("    " + o.message.replace("\n", "\n    "), file=sys.stderr)

    from .build import OutputError

    try:
        outcomes = build(args.paths, opts, jobs=args.jobs, progress=progress)
    except OutputError as exc:
        print(f"balpipe: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    if not outcomes:
        print("balpipe: error: no spec files (*.yaml) found", file=sys.stderr)
        return EXIT_USAGE
    n_err = sum(o.spec_error for o in outcomes)
    n_fail = sum(o.status in ("failed", "crash") for o in outcomes)
    n_ok = len(outcomes) - n_err - n_fail
    print(f"balpipe: {n_ok} ok, {n_fail} failed, {n_err} invalid; site: {opts.out / 'index.html'}", file=sys.stderr)
    if n_fail:
        return EXIT_FAILED
    return EXIT_USAGE if n_err else EXIT_OK


def cmd_check(args) -> int:
    """Everything ``build`` checks before simulating: schema, units, limits, geometry, the
    balancing, the analysis of every stage (singular motions) and the references. Keeps going
    past a spec that fails."""
    from .build import _clashes, analyse, find_specs
    from .loader import SpecErrors, load

    missing = _missing(args.paths)
    if missing:
        print(f"balpipe: error: no such file or folder: {', '.join(missing)}", file=sys.stderr)
        return EXIT_USAGE
    problems: list[str] = []
    files = find_specs(args.paths, problems)
    for msg in problems:
        print(msg, file=sys.stderr)
    clash = _clashes(files)
    bad = crashed = 0
    for f in files:
        try:
            if f in clash:
                raise SpecErrors([])
            analyse(load(f))
            print(f"{f}: ok")
        except SpecErrors as exc:
            bad += 1
            print(str(exc) or clash[f], file=sys.stderr)
        except Exception as exc:  # a bug in balpipe: report it, check the other specs
            crashed += 1
            print(f"{f}: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
    bad += len(problems)
    print(f"balpipe: {len(files) - bad - crashed + len(problems)} valid, {bad} invalid"
          + (f", {crashed} internal errors" if crashed else ""), file=sys.stderr)
    if not files and not problems:
        return EXIT_USAGE
    if crashed:
        return EXIT_FAILED
    return EXIT_USAGE if bad else EXIT_OK


def cmd_diff(args) -> int:
    from . import diff
    from .loader import SpecErrors

    try:
        a = diff.run_side(args.old, simulate=not args.no_sim)
        b = diff.run_side(args.new, simulate=not args.no_sim)
    except SpecErrors as exc:
        print(str(exc), file=sys.stderr)
        return EXIT_USAGE
    data = diff.compare(a, b)
    text = (diff.to_html(data, a, b, site=diff.site_link(args.site, args.out)) if args.format == "html"
            else diff.RENDERERS[args.format](data))
    return _emit(text, args.out)


def _emit(text: str, out: str | None) -> int:
    """Write ``text`` to the file ``out`` (or stdout); a path that cannot be written is a usage
    error with the reason, not a traceback."""
    if not out:
        sys.stdout.write(text)
        return EXIT_OK
    try:
        Path(out).write_text(text, encoding="utf-8")
    except OSError as exc:
        print(f"balpipe: error: cannot write {out}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_USAGE
    return EXIT_OK


def cmd_schema(args) -> int:
    from .loader import schema

    text = json.dumps(schema(), indent=2, sort_keys=True) + "\n"
    return _emit(text, args.out)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    else:  # pragma: no cover - embedded use
        previous = None
    try:
        if args.command == "history":  # balpipe.history_cli
            from .history_cli import cmd_history

            return cmd_history(args)
        from .cli_sweep import cmd_sweep

        return {"build": cmd_build, "check": cmd_check, "diff": cmd_diff, "schema": cmd_schema,
                "sweep": cmd_sweep}[args.command](args)
    except Terminated:
        print("balpipe: terminated; the site is as the last complete build left it", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("balpipe: interrupted; the site is as the last complete build left it", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
