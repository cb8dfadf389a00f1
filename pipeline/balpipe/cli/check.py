"""``balpipe check PATH...``: validate specs without building."""

from __future__ import annotations

import sys

from .common import EXIT_FAILED, EXIT_OK, EXIT_USAGE, paths_jobs_problem, usage_error


def add_parser(sub) -> None:
    c = sub.add_parser("check", help="validate specs without building",
                       description="Check specs: schema, units, geometry and balancing feasibility.")
    c.add_argument("paths", nargs="+", metavar="PATH", help="spec files or folders of specs")
    c.add_argument("-j", "--jobs", type=int, default=None, metavar="N",
                   help="check N specs in parallel (default: one per usable core, at most one per spec; "
                   "1: one after another); the output is the same")


def check_one(f, clash: str | None) -> tuple[str, str]:
    """(verdict, message) of one spec file: ("ok", ...), ("invalid", the located errors) or
    ("crashed", the internal error). ``clash``: the spec's page-name clash, if any."""
    from ..loader import SpecErrors, load
    from ..runner import analyse

    try:
        if clash is not None:
            return "invalid", clash
        loaded = load(f)
        analyse(loaded, page=False)  # what only the page shows cannot make a spec invalid
        if loaded.spec.sweep is not None:  # its paths and values against the spec, as balpipe sweep does
            from ..sweep import SweepError, plan  # only for a spec with a sweep block

            try:
                plan(str(f))
            except SweepError as exc:
                raise SpecErrors([]) from exc
        return "ok", f"{f}: ok"
    except SpecErrors as exc:
        return "invalid", str(exc) or str(exc.__cause__ or "")
    except Exception as exc:  # a bug in balpipe: report it, check the other specs
        return "crashed", f"{f}: internal error: {type(exc).__name__}: {exc}"


def run(args) -> int:
    """Everything ``build`` checks before simulating: schema, units, limits, geometry, the
    balancing, the analysis of every stage (singular motions), the references, and the paths and
    values of a ``sweep:`` block. Keeps going past a spec that fails. With several specs, in
    ``--jobs`` processes, the costliest started first (:func:`balpipe.site_files.check_cost.check_cost`);
    the messages come in the specs' order whatever the number."""
    import gc

    problem = paths_jobs_problem(args.paths, args.jobs)
    if problem:
        return usage_error(problem)
    # the modules' objects live as long as the process: made with the collector off and frozen
    # right after, so that no collection scans them (a one-spec check's collections 0.015 ->
    # 0.002 s of CPU); the objects made from here on are collected as usual
    gc.disable()
    try:
        from .. import loader, runner  # noqa: F401  (loaded once here, before the workers fork)
        gc.freeze()
    finally:
        gc.enable()
    try:
        return _check(args.paths, args.jobs)
    finally:
        gc.unfreeze()  # as it was for a caller in the same process (tests)


def _check(paths: list[str], jobs_asked: int | None) -> int:
    """:func:`run` once its modules are loaded (and frozen)."""
    import gc

    from .. import loader
    from ..site_files.check_cost import check_hints
    from ..runtime.pool import default_jobs, finished, in_order
    from ..site_files.spec_files import clashes, find_specs

    problems: list[str] = []
    files = find_specs(paths, problems)
    for msg in problems:
        print(msg, file=sys.stderr)
    clash = clashes(files)
    jobs = jobs_asked if jobs_asked is not None else default_jobs(len(files))
    # with workers: each spec's expected cost and method, its names read once for both
    hints = {f: check_hints(f) for f in files} if jobs > 1 and len(files) > 1 else {}
    if len(files) > 1:
        # the whole schema, frozen below and built once (not in every worker, nor narrowed per spec;
        # one spec is validated by its own sections alone, balpipe.spec.validate), and the methods'
        # libraries: objects that live as long as the process, not scanned by the collector while
        # they are made (the parent's collections 0.041 -> 0.011 s of CPU)
        gc.disable()
        try:
            loader.prepare()
            if hints:
                _load_methods_code([method for _, method in hints.values()])
        finally:
            gc.enable()
    # the schema's and the libraries' objects live as long as the process: the collector stops
    # scanning them at each full collection (10-20 % of the checks' CPU) and forked workers stop
    # copying their pages (the objects made from here on are collected as usual)
    gc.freeze()
    with finished(in_order(_check_item, [(f, clash.get(f)) for f in files], jobs,
                           cost=(lambda item: hints[item[0]][0]) if hints else None)) as results:
        bad, crashed = _report(results)
    bad += len(problems)
    print(f"balpipe: {len(files) - bad - crashed + len(problems)} valid, {bad} invalid"
          + (f", {crashed} internal errors" if crashed else ""), file=sys.stderr)
    if not files and not problems:
        return EXIT_USAGE
    if crashed:
        return EXIT_FAILED
    return EXIT_USAGE if bad else EXIT_OK


def _load_methods_code(methods: list[str | None]) -> None:
    """Before the pool forks: the code of the ``methods`` the specs name and the libraries it
    imports when it runs (:attr:`balpipe.plugins.Method.imports`, scipy's optimiser: 0.3 s),
    loaded once here rather than again in every worker. The names are read with the costs
    (:func:`balpipe.site_files.check_cost.check_hints`); a spec whose name cannot be read (None)
    is left to its worker."""
    from .. import registry

    for name in dict.fromkeys(methods):
        method = registry.METHODS.get(name or "")
        if method is not None:
            method.load_code()


def _report(results) -> tuple[int, int]:
    """Print each (verdict, message), valid ones to stdout; (invalid, crashed) counts."""
    bad = crashed = 0
    for verdict, message in results:
        if verdict == "ok":
            print(message)
            continue
        bad += verdict == "invalid"
        crashed += verdict == "crashed"
        print(message, file=sys.stderr)
    return bad, crashed


def _check_item(item: tuple) -> tuple[str, str]:
    return check_one(*item)
