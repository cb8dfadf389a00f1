"""The report site as a team meets it: served from a subfolder of a web server
(``python -m http.server``), every page and asset loads in a real browser with no console error
and no 404, the links stay relative, and the index's search and filter work.

The browser is the system's Chromium driven by playwright for Python (``pip install '.[test]'``;
no browser download: ``executable_path`` points at the installed one, ``BALPIPE_CHROMIUM``
overrides it). Without either, the browser tests are skipped with the reason; the static check
of the links runs everywhere.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import urljoin, urlsplit

import numpy as np
import pytest

from _gitrepo import Repo, edit

from balpipe import history
from balpipe.build import Options, build

# one xdist worker runs the whole module and tests/report/test_live_browser.py (addopts --dist loadgroup):
# their sites and the browser (the session's ``browser`` fixture, tests/conftest.py) are made once
# per run, not once per worker
pytestmark = pytest.mark.xdist_group("site_browser")

SUBFOLDER = "team/balpipe"


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """A git repository of three specs (one with two commits, one invalid), its history and a
    simulated build, written to <root>/team/balpipe; returns <root>."""
    tmp = tmp_path_factory.mktemp("site")
    repo = Repo(tmp / "repo")
    repo.copy_spec("scott_russell.yaml", "specs/scott_russell.yaml")
    repo.copy_spec("offset_slider_crank.yaml", "specs/osc.yaml")
    repo.commit("two designs", {"specs/scott_russell.yaml": repo.read("specs/scott_russell.yaml"),
                                "specs/osc.yaml": repo.read("specs/osc.yaml")})
    repo.commit("heavier slider", {"specs/osc.yaml": edit(repo.read("specs/osc.yaml"), "{mass: 600 g}", "{mass: 700 g}")})
    repo.commit("a broken spec", {"specs/broken.yaml": "name: broken\nmechanism: {template: slider_crank\n"})
    root = tmp / "www"
    out = root / SUBFOLDER
    cwd = os.getcwd()
    os.chdir(repo.path)
    try:
        history.run(["specs"], out, tmp / "cache", simulate=False)
        outcomes = build(["specs"], Options(out=out, simulate=True))
    finally:
        os.chdir(cwd)
    assert sorted(o.status for o in outcomes) == ["error", "ok", "ok"], [o.message for o in outcomes]
    (root / "index.html").write_text("<!doctype html><title>another site</title>\n")  # the server's own root
    return root


@pytest.fixture(scope="module")
def server(site):
    """``python -m http.server`` on 127.0.0.1 and a free port, serving the folder above the site."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "http.server", str(port), "--bind", "127.0.0.1",
                             "--directory", str(site)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = f"http://127.0.0.1:{port}/"
    try:
        deadline = time.monotonic() + 20
        while True:
            try:
                urllib.request.urlopen(base, timeout=1).close()
                break
            except (urllib.error.URLError, OSError):
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError("http.server did not start")
                time.sleep(0.1)
        yield base + SUBFOLDER + "/"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


class Watched:
    """A browser page that records console errors, page errors, failed requests, HTTP errors and
    every URL it requested."""

    def __init__(self, browser):
        self.page = browser.new_page()
        self.problems: list[str] = []
        self.requested: list[str] = []
        p = self.page
        p.on("console", lambda m: self.problems.append(f"console {m.type}: {m.text} ({p.url})")
             if m.type in ("error", "assert") else None)
        p.on("pageerror", lambda e: self.problems.append(f"JavaScript error: {e} ({p.url})"))
        p.on("requestfailed", lambda r: self.problems.append(f"request failed: {r.url} ({r.failure})"))
        p.on("response", lambda r: self.problems.append(f"HTTP {r.status}: {r.url}") if r.status >= 400 else None)
        p.on("request", lambda r: self.requested.append(r.url))


def test_every_page_and_asset_loads_from_a_subfolder(site, server, browser):
    w = Watched(browser)
    pages, assets, queue = set(), set(), [server + "index.html"]
    while queue:
        url = queue.pop(0)
        if url in pages:
            continue
        pages.add(url)
        resp = w.page.goto(url, wait_until="load")
        assert resp is not None and resp.status == 200, url
        w.page.wait_for_timeout(150)  # let the page's scripts run (player, timing, filter)
        check_figures_and_anchors(w.page, url)
        for href in w.page.eval_on_selector_all("a[href]", "els => els.map(e => e.href)"):
            target = href.split("#")[0]
            assert target.startswith(server), f"{url} links outside the site's folder: {href}"
            if target.endswith(".html"):
                queue.append(target)
            else:
                assets.add(target)
    for a in sorted(assets):
        r = w.page.request.get(a)
        assert r.status == 200, f"{a}: HTTP {r.status}"
    on_disk = {server + p.relative_to(site / SUBFOLDER).as_posix() for p in (site / SUBFOLDER).rglob("*.html")}
    assert on_disk == pages, f"pages not reachable from the index: {sorted(on_disk - pages)}"
    outside = [u for u in w.requested if not (u.startswith(server) or u.startswith("data:"))]
    assert not outside, f"requests outside the site's folder: {outside}"
    assert not w.problems, "\n".join(w.problems)
    # what was loaded: three study pages, two history pages, their data files and scripts
    names = {u[len(server):] for u in pages | assets | set(w.requested)}
    for expected in ("scott_russell/index.html", "osc/history.html", "osc/history.json", "osc/results.json",
                     "osc/timeseries.csv", "scott_russell/timing.js", "balpipe.schema.json"):
        assert expected in names, expected


def check_figures_and_anchors(page, url: str) -> None:
    """Every figure is visible with a real size, and every in-page link (the table of contents)
    names an element of the page."""
    page.evaluate("document.querySelectorAll('details').forEach(d => d.open = true)")  # collapsed sections
    page.wait_for_timeout(50)
    figs = page.locator("figure")
    for k in range(figs.count()):
        f = figs.nth(k)
        f.scroll_into_view_if_needed()
        box = f.bounding_box()
        assert f.is_visible() and box and box["width"] > 100 and box["height"] > 50, f"{url}: figure {k} not visible"
        inner = f.locator("svg, canvas, img")
        if inner.count():
            b = inner.first.bounding_box()
            assert b and b["width"] > 100 and b["height"] > 50, f"{url}: figure {k}'s drawing has no size"
    sw, cw = page.evaluate("[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
    assert sw <= cw + 1, f"{url}: the page is wider than the window ({sw} > {cw} px)"
    missing = page.evaluate("""() => [...document.querySelectorAll('a[href^="#"]')]
        .map(a => a.getAttribute('href').slice(1)).filter(id => id && !document.getElementById(id))""")
    assert not missing, f"{url}: in-page links to nothing: {missing}"


def test_study_pages_have_contents_and_links_between_studies(server, browser):
    w = Watched(browser)
    p = w.page
    p.goto(server + "osc/index.html", wait_until="load")
    toc = p.eval_on_selector_all("nav.toc a", "els => els.map(e => e.textContent)")
    assert "Balancing stages" in toc and "Inputs" in toc and "What balancing costs the actuators" in toc
    # site_nav.js: the index's order is broken (invalid, no page), osc, scott_russell
    nxt = p.eval_on_selector_all("a[rel=next]", "els => els.map(e => e.href)")
    prev = p.eval_on_selector_all("a[rel=prev]", "els => els.map(e => e.href)")
    assert nxt and all(h == server + "scott_russell/index.html" for h in nxt) and not prev
    p.click("#sitenav a[rel=next]")
    p.wait_for_load_state("load")
    assert p.url == server + "scott_russell/index.html"
    assert p.eval_on_selector_all("a[rel=prev]", "els => els.map(e => e.href)")[0] == server + "osc/index.html"
    assert p.locator("table.inputs").count() == 1 and "kg" in p.text_content("table.inputs")
    # the print stylesheet hides the navigation and the player's controls
    p.emulate_media(media="print")
    assert not p.is_visible("nav.toc") and not p.is_visible("header.top") and not p.is_visible(".player-controls")
    p.emulate_media(media="screen")
    assert p.is_visible("nav.toc")
    assert not w.problems, "\n".join(w.problems)


#: every live figure of the page built (live_plots.js builds a figure when its section opens)
ALL_BUILT = """() => [...document.querySelectorAll("script[data-live]")].every(s => {
  const h = document.getElementById(s.dataset.live);
  return !h || h.classList.contains("live-ready") || h.classList.contains("live-empty"); })"""


def open_sections(page) -> None:
    """Open the page's collapsed sections, as a reader does to reach the player, and wait until
    the figures they hold are built."""
    page.evaluate("document.querySelectorAll('details').forEach(d => d.open = true)")
    page.wait_for_function(ALL_BUILT)
    page.wait_for_timeout(50)


PRINT_RATIO = 3  # templates/live_plots.js: device pixels per CSS pixel of a plot drawn for print
# How long a print copy may take to appear or go: waiting returns as soon as it holds, the limit
# only matters on a loaded machine (5 s failed once at a load average of 21 on 2 cores).
PRINT_WAIT_MS = 30_000

_PRINTED = """host => {
  const style = getComputedStyle(host);
  const columns = style.display === "grid" ? style.gridTemplateColumns.split(" ").length : 1;
  return { width: host.clientWidth, columns: columns, plots: [...host.querySelectorAll(".live-plot")].map(el => {
    const c = el.querySelector(".live-print canvas"), screen = el.querySelector(":scope > .uplot");
    if (!c) return null;
    const box = c.getBoundingClientRect(), wrap = c.parentNode;
    return { width: box.width, height: box.height, pixels: c.width, drawn: parseFloat(wrap.style.width),
             screen: screen.getBoundingClientRect().height };
  }) };
}"""


def assert_printed(page, figure: str) -> None:
    """In print media every panel of the live figure ``#figure`` is drawn for print: a canvas of
    PRINT_RATIO device pixels per CSS pixel, stretched across its share of the printed width (a
    figure of small multiples: two a row), the screen's plot hidden, and every panel shown (a
    joint selector's too); back on screen the print copies are gone. The media query is what
    Playwright's emulation and the print layout change (page.pdf and the print dialog also send
    beforeprint: :func:`test_a_pdf_prints_every_panel_drawn_for_print`)."""
    page.emulate_media(media="print")
    try:
        page.wait_for_function(f"document.querySelectorAll('#{figure} .live-print canvas').length === "
                               f"document.querySelectorAll('#{figure} .live-plot').length", timeout=PRINT_WAIT_MS)
        got = page.eval_on_selector(f"#{figure}", _PRINTED)
        assert got["plots"] and all(got["plots"]), got
        column = got["width"] / got["columns"]
        for plot in got["plots"]:
            assert plot["width"] >= 0.9 * column and plot["height"] > 0.2 * plot["width"], (figure, plot, column)
            assert plot["pixels"] >= PRINT_RATIO * plot["drawn"] - 1, (figure, plot)  # sharp on paper
            assert plot["screen"] == 0, (figure, plot)  # the screen's plot is not printed
        assert not page.is_visible(f"#{figure} .live-choose")
    finally:
        page.emulate_media(media="screen")
    page.wait_for_function(f"!document.querySelector('#{figure} .live-print')", timeout=PRINT_WAIT_MS)
    assert page.is_visible(f"#{figure} .live-plot:not([hidden]) > .uplot canvas")


def test_player_pauses_scrubs_and_answers_the_keyboard(server, browser):
    w = Watched(browser)
    p = w.page
    p.goto(server + "scott_russell/index.html", wait_until="load")
    open_sections(p)
    p.locator("#player").scroll_into_view_if_needed()
    p.wait_for_timeout(300)
    assert p.get_attribute("#player", "data-playing") == "1"  # plays by default, in real time
    assert p.eval_on_selector("#player-speed", "s => s.value") == "1"
    assert "1× real time" in p.text_content("#player-clock")
    t0 = p.text_content("#player-clock")
    # it moves: waited for as an event (a loaded machine may paint late), not for a fixed time
    p.wait_for_function("t0 => document.querySelector('#player-clock').textContent !== t0", arg=t0, timeout=60_000)
    p.click("#player-play")  # pause
    assert p.get_attribute("#player", "data-playing") == "0" and p.text_content("#player-play") == "Play"
    paused = p.text_content("#player-clock")
    pixels = p.eval_on_selector("#player", "c => c.toDataURL()")
    p.wait_for_timeout(250)
    assert p.text_content("#player-clock") == paused and p.eval_on_selector("#player", "c => c.toDataURL()") == pixels
    # scrub: the slider sets the time and the drawing
    p.eval_on_selector("#player-time", "s => { s.value = '500'; s.dispatchEvent(new Event('input')); }")
    clock = p.text_content("#player-clock")
    m = re.match(r"t = (\d+\.\d+) s of (\d+\.\d+) s", clock)
    assert m and abs(float(m.group(1)) - 0.5 * float(m.group(2))) < 1e-3, clock
    assert p.eval_on_selector("#player", "c => c.toDataURL()") != pixels
    p.eval_on_selector("#player-time", "s => { s.value = '1000'; s.dispatchEvent(new Event('input')); }")
    assert re.match(r"t = (\S+) s of \1 s", p.text_content("#player-clock"))
    # keyboard: arrows step back, space plays again
    p.focus("#player")
    p.keyboard.press("ArrowLeft")
    assert not re.match(r"t = (\S+) s of \1 s", p.text_content("#player-clock"))
    p.keyboard.press(" ")
    assert p.get_attribute("#player", "data-playing") == "1"
    p.focus("#player-play")
    p.keyboard.press("Enter")  # the button is a real button
    assert p.get_attribute("#player", "data-playing") == "0"
    assert not w.problems, "\n".join(w.problems)


def test_player_names_its_parts_and_shows_a_scale_bar_per_panel(server, browser):
    """The player's names (pivots, joints, links, counterweights) are drawn, none over another
    (the placer leaves out what does not fit), and can be switched off; the caption says how
    the panels' scales compare."""
    w = Watched(browser)
    p = w.page
    p.goto(server + "scott_russell/index.html", wait_until="load")
    open_sections(p)
    p.click("#player-play")  # pause
    p.eval_on_selector("#player-time", "s => { s.value = '300'; s.dispatchEvent(new Event('input')); }")
    named = p.eval_on_selector("#player", "c => Object.keys(c.dataset).filter(k => k.startsWith('names')).map(k => +c.dataset[k])")
    # the demonstration's stages: the reactionless one ("full") and its unbalanced reference
    assert len(named) == 2 and all(n >= 5 for n in named), named  # A, B, C, crank, coupler at least
    pixels = p.eval_on_selector("#player", "c => c.toDataURL()")
    p.uncheck("#player-names")
    assert p.eval_on_selector("#player", "c => c.dataset.names0") == "0"
    assert p.eval_on_selector("#player", "c => c.toDataURL()") != pixels
    p.focus("#player-names")
    p.keyboard.press(" ")  # a real checkbox: the keyboard turns the names back on
    assert p.is_checked("#player-names") and p.eval_on_selector("#player", "c => +c.dataset.names0") >= 5
    caption = p.text_content("figure:has(#player) figcaption")
    assert "scale bar" in caption and ("scales differ" in caption or "same scale" in caption)
    assert not w.problems, "\n".join(w.problems)


def test_scripts_ran_in_the_pages(server, browser):
    w = Watched(browser)
    w.page.goto(server + "scott_russell/index.html", wait_until="load")
    cells = w.page.eval_on_selector_all("[data-timing]", "els => els.map(e => e.textContent)")
    assert cells and all(re.fullmatch(r"\d+\.\d{3} s", c) for c in cells), cells  # timing.js filled them
    assert w.page.eval_on_selector("canvas", "c => c.width") > 0  # the reactionless player
    assert w.page.locator("#history").count() == 1
    assert not w.problems, "\n".join(w.problems)


def visible_specs(page) -> list[str]:
    return page.eval_on_selector_all(
        "#studies tbody.entry", "els => els.filter(e => !e.hidden).map(e => e.dataset.text)")


def test_index_search_and_filters(server, browser):
    w = Watched(browser)
    p = w.page
    p.goto(server + "index.html", wait_until="load")
    assert len(visible_specs(p)) == 3 and p.text_content("#f-count") == "3 of 3 shown"
    options = p.eval_on_selector_all("#f-method option", "els => els.map(e => e.value)")
    assert options == ["", "slider_crank_counterweights"]
    p.select_option("#f-method", "slider_crank_counterweights")
    assert len(visible_specs(p)) == 2  # the invalid spec has no method
    p.fill("#f-q", "scott russell")
    shown = visible_specs(p)
    assert len(shown) == 1 and "scott-russell" in shown[0]
    assert p.text_content("#f-count") == "1 of 3 shown"
    p.press("#f-q", "Enter")  # no form submission, no reload
    assert "?" not in p.url and len(visible_specs(p)) == 1
    assert "q=scott%20russell" in p.evaluate("location.hash") and "method=" in p.evaluate("location.hash")
    p.fill("#f-q", "no such study")
    assert visible_specs(p) == [] and p.is_visible("#f-none")
    # a shared link restores the filter
    p.goto(server + "index.html#status=invalid", wait_until="load")
    p.reload(wait_until="load")
    shown = visible_specs(p)
    assert len(shown) == 1 and "broken" in shown[0]
    assert p.eval_on_selector("#f-status", "s => s.value") == "invalid"
    assert p.eval_on_selector_all("#f-status option", "els => els.map(e => e.value)") == ["", "invalid", "ok"]
    papers = p.eval_on_selector_all("#f-paper option", "els => els.map(e => e.value)")
    assert any(v.startswith("000:") for v in papers)
    p.select_option("#f-status", "")
    p.select_option("#f-paper", next(v for v in papers if v.startswith("000:")))
    assert len(visible_specs(p)) == 2
    assert not w.problems, "\n".join(w.problems)


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.urls: list[str] = []

    def handle_starttag(self, tag, attrs):
        for k, v in attrs:
            if k in ("href", "src", "xlink:href", "action") and v is not None:
                self.urls.append(v)


def test_links_are_relative_and_resolve(site):
    """Without a browser too: every href and src in every page is relative and names a file of
    the site, so the site works from any folder of any server (and from file://)."""
    top = site / SUBFOLDER
    for page in sorted(top.rglob("*.html")):
        parser = _Links()
        parser.feed(page.read_text(encoding="utf-8"))
        for url in parser.urls:
            if url.startswith("#") or url.startswith("data:"):
                continue
            parts = urlsplit(url)
            assert not parts.scheme and not parts.netloc and not url.startswith("/"), f"{page}: {url}"
            target = Path(urljoin(page.as_posix(), parts.path))
            assert target.exists() and top in target.resolve().parents, f"{page}: {url} -> {target}"


def test_the_watcher_sees_a_missing_asset_and_a_script_error(site, server, browser):
    """Negative control: a page outside the site with a missing script and a failing one."""
    probe = site / "probe"
    probe.mkdir(exist_ok=True)
    (probe / "page.html").write_text('<!doctype html><link rel="icon" href="data:,"><title>probe</title>'
                                     '<script src="missing.js"></script><script>undefinedFunction()</script>\n')
    w = Watched(browser)
    w.page.goto(server.replace(SUBFOLDER + "/", "probe/page.html"), wait_until="load")
    assert any(p.startswith("HTTP 404") and p.endswith("/probe/missing.js") for p in w.problems), w.problems
    assert any("undefinedFunction" in p for p in w.problems), w.problems


# ------------------------------------------------------------------------------------------
# Layout (issue 22): every built page at 400 px and 1400 px


PAPER_SPECS = ("custom_four_bar_balancing.yaml", "paper000_rpr3_scott_russell.yaml", "paper002_decoupling.yaml")
SCREENS = 12  # a page is at most this many screens long at 1400 px with its sections collapsed (close all)
MAX_BYTES = 2_000_000  # and weighs less than this (the page with everything it loads)


@pytest.fixture(scope="module")
def paper_site(tmp_path_factory) -> Path:
    """Three paper and custom specs built without simulation (their pages are the longest)."""
    out = tmp_path_factory.mktemp("papers") / "site"
    specs = Path(__file__).resolve().parents[2] / "specs"
    outcomes = build([str(specs / s) for s in PAPER_SPECS], Options(out=out, simulate=False))
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    # and a diff page beside them (balpipe diff -f html), a page of the site as well
    new = out.parent / "heavier.yaml"
    new.write_text((specs / "offset_slider_crank.yaml").read_text().replace("{mass: 600 g}", "{mass: 700 g}"))
    r = subprocess.run([sys.executable, "-m", "balpipe", "diff", str(specs / "offset_slider_crank.yaml"), str(new),
                        "--no-sim", "-f", "html", "-o", str(out / "diff.html")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out


# Elements whose content spills out of their box: clipped (overflow hidden/auto) or drawn over
# their neighbours (overflow visible). Measured from the laid-out boxes.
_SPILLS = """() => {
  const out = [];
  const vw = document.documentElement.clientWidth;
  for (const el of document.querySelectorAll(
      'main td, main th, main p, main li, main dd, main dt, main h1, main h2, main h3, main summary, main figcaption, header.top, main span.badge, main code, main pre')) {
    const r = el.getBoundingClientRect();
    if (!r.width || !r.height || el.offsetParent === null) continue;
    const text = (el.textContent || '').trim().slice(0, 60);
    if (r.right > vw + 1 || r.left < -1) out.push(`outside the window (${Math.round(r.left)}..${Math.round(r.right)} of ${vw} px): ${el.tagName} "${text}"`);
    const cs = getComputedStyle(el);
    if (cs.display === 'inline') continue;
    if (el.scrollWidth > el.clientWidth + 1) out.push(`spills ${el.scrollWidth - el.clientWidth} px (overflow ${cs.overflowX}): ${el.tagName} "${text}"`);
  }
  // cells of one row never overlap
  for (const tr of document.querySelectorAll('main tr')) {
    const cells = [...tr.cells].map(c => c.getBoundingClientRect()).filter(r => r.width && r.height);
    for (let i = 1; i < cells.length; i++) {
      const a = cells[i - 1], b = cells[i];
      const overlapX = Math.min(a.right, b.right) - Math.max(a.left, b.left);
      const overlapY = Math.min(a.bottom, b.bottom) - Math.max(a.top, b.top);
      if (overlapX > 1 && overlapY > 1) out.push(`cells overlap in a row: "${(tr.textContent || '').trim().slice(0, 60)}"`);
    }
  }
  return out;
}"""


# Text of a drawing (SVG) shown smaller than MIN_TEXT_PX: a wide figure squeezed into a narrow
# window. Size on screen = the text's font size times the scale of its transform to the screen.
MIN_TEXT_PX = 6
_SMALL_TEXT = """min => {
  const out = [];
  for (const svg of document.querySelectorAll('main svg')) {
    if (!svg.getBoundingClientRect().width) continue;  // not shown (the print copy of a live plot)
    let small = Infinity, text = '';
    for (const t of svg.querySelectorAll('text')) {
      const m = t.getScreenCTM();
      const size = m ? parseFloat(getComputedStyle(t).fontSize) * Math.hypot(m.a, m.b) : Infinity;
      if (size < small) { small = size; text = t.textContent; }
    }
    if (small < min) {
      const cap = svg.closest('figure')?.querySelector('figcaption')?.textContent.trim().slice(0, 60) || '';
      out.push(`drawing text ${small.toFixed(1)} px on screen (< ${min} px), "${text}" in the figure "${cap}"`);
    }
  }
  return out;
}"""


def _pages(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*.html") if "probe" not in p.parts)


def _weight(page: Path) -> int:
    """Bytes of a page and the local files it loads (scripts, styles, images)."""
    parser = _Links()
    parser.feed(page.read_text(encoding="utf-8"))
    total = page.stat().st_size
    for url in parser.urls:
        if url.endswith((".js", ".css", ".png", ".svg")) and not url.startswith(("data:", "#")):
            f = Path(urljoin(page.as_posix(), urlsplit(url).path))
            total += f.stat().st_size if f.exists() else 0
    return total


def page_problems(ctx, page_file: Path, width: int) -> list[str]:
    """What a reader meets on one built page opened from file:// (as a downloaded site) in a
    window ``width`` px wide: a page longer than SCREENS windows at 1400 px with its sections
    closed by its own "close all" (the paper's figures open at load by design), then, with every section open, a page that scrolls sideways, text clipped
    or drawn over its neighbours (_SPILLS), drawings whose text is too small to read (_SMALL_TEXT),
    and console errors, script errors or failed loads."""
    w = Watched(ctx)
    p = w.page
    url = page_file.as_uri()
    problems = []
    try:
        p.goto(url, wait_until="load")
        p.wait_for_timeout(100)
        if width == 1400:
            # the overview a reader gets with the page's own "close all" (the paper's figures are
            # open at load by design, so the page as it opens may be longer)
            close_all = p.locator(".toc-all button", has_text="close all")
            if close_all.count():
                close_all.first.click()
            height = p.evaluate("document.documentElement.scrollHeight")
            if height > SCREENS * 900:
                problems.append(f"{url}: {height} px long with its sections collapsed (> {SCREENS} screens)")
        open_sections(p)
        p.wait_for_timeout(100)  # the opened sections' tables and plots take their width
        sw, cw = p.evaluate("[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
        if sw > cw + 1:
            problems.append(f"{url}: scrolls sideways ({sw} > {cw} px)")
        problems += [f"{url}: {s}" for s in p.evaluate(_SPILLS) + p.evaluate(_SMALL_TEXT, MIN_TEXT_PX)]
        return problems + w.problems
    finally:
        p.close()


def layout_context(browser, width: int):
    return browser.new_context(viewport={"width": width, "height": 900})


@pytest.mark.parametrize("width", [400, 1400])
def test_every_page_fits_the_window_with_nothing_clipped(site, paper_site, browser, width):
    problems = []
    ctx = layout_context(browser, width)
    try:
        for top in (site / SUBFOLDER, paper_site):
            for page_file in _pages(top):
                problems += page_problems(ctx, page_file, width)
    finally:
        ctx.close()
    assert not problems, f"{len(problems)} problems at {width} px:\n" + "\n".join(problems[:40])


def test_every_page_weighs_less_than_2_mb(site, paper_site):
    heavy = [(p, _weight(p)) for top in (site / SUBFOLDER, paper_site) for p in _pages(top)]
    assert heavy and all(n < MAX_BYTES for _, n in heavy), [(str(p), n) for p, n in heavy if n >= MAX_BYTES]


def test_index_verdicts_agree_with_results_json(paper_site, browser):
    import json

    w = Watched(browser)
    w.page.goto((paper_site / "index.html").as_uri(), wait_until="load")
    shown = w.page.eval_on_selector_all(
        "#studies tbody.entry", "els => els.map(e => [e.dataset.spec, e.dataset.verdict, e.querySelector('.verdict .badge').textContent])")
    assert len(shown) == len(PAPER_SPECS)
    for slug, level, words in shown:
        v = json.loads((paper_site / slug / "results.json").read_text(encoding="utf-8"))["verdict"]
        assert (level, words) == (v["level"], v["words"]), slug
    assert not w.problems, "\n".join(w.problems)


_LEGEND_VALUES = "el => [...el.querySelectorAll('.u-legend .u-series .u-value')].map(v => v.textContent)"
_CURSOR_TIME = "el => el.querySelector('.u-legend .u-series .u-value').textContent"


def hover(page, plot, min_width: int = 200) -> list[str]:
    """Move the mouse over a live plot (a .live-plot), 40 % along its time axis, and read its
    legend: the time and every curve's value there. The plot must be drawn, its plotting area
    wider than ``min_width`` px."""
    over = plot.locator(".u-over")  # the plotting area itself: a legend of many curves (paper 003's
    over.scroll_into_view_if_needed()  # 96 at 400 px) makes the plot taller than the window
    box = over.bounding_box()
    assert box and box["width"] > min_width, f"no interactive plot drawn ({box})"
    page.mouse.move(box["x"] + box["width"] * 0.4, box["y"] + box["height"] * 0.5)
    return plot.evaluate(_LEGEND_VALUES)


def test_hovering_a_plot_shows_its_values_and_a_click_hides_a_curve(paper_site, browser):
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.goto((paper_site / "paper002_decoupling" / "index.html").as_uri(), wait_until="load")
    plot = p.locator("#live-loads .live-plot").first
    shown = hover(p, plot)
    assert shown and all(re.search(r"\d", v) for v in shown), shown  # time and every curve's value
    # a click on a legend entry hides its curve
    entry = plot.locator(".u-legend .u-series").nth(1)
    entry.click()
    assert "u-off" in (entry.get_attribute("class") or "")
    # no static figure: printing prints the live plot, drawn again for print, the hidden curve hidden
    assert not p.locator(".static-plot").count() and not p.locator("#live-loads svg:not(.swatch-svg)").count()
    label = entry.locator(".u-label").text_content()
    p.emulate_media(media="print")
    p.wait_for_selector("#live-loads .live-print .u-legend", state="attached")
    off = plot.evaluate("""(el, label) => [...el.querySelectorAll(".live-print .u-legend .u-series")]
        .map(r => [r.querySelector(".u-label").textContent, r.classList.contains("u-off")])""", label)
    assert [hidden for name, hidden in off if name == label] == [True] and [h for _, h in off].count(True) == 1, off
    p.emulate_media(media="screen")
    assert_printed(p, "live-loads")
    assert not w.problems, "\n".join(w.problems)


def test_a_pdf_prints_every_panel_drawn_for_print(paper_site, browser):
    """Playwright's page.pdf, as the print dialog, sends beforeprint with the screen's layout:
    by then every panel of every live figure (the joints' hidden ones too, and those of the
    collapsed sections, which printing opens: fit_tables.js) is drawn for print; after it the
    print copies are gone and the screen's plots are drawn as before."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.goto((paper_site / "paper002_decoupling" / "index.html").as_uri(), wait_until="load")
    p.evaluate("""addEventListener("beforeprint", () => { window.printedPanels = [...document.querySelectorAll(".live-plot")]
        .map(el => { const c = el.querySelector(".live-print canvas"); return c ? c.width / parseFloat(c.parentNode.style.width) : 0; }); })""")
    pdf = p.pdf()
    assert pdf.startswith(b"%PDF") and len(pdf) > 10_000
    ratios = p.evaluate("window.printedPanels")
    assert ratios and len(ratios) == p.locator(".live-plot").count() and min(ratios) >= PRINT_RATIO - 0.01, ratios
    assert not p.locator(".live-print").count()
    assert p.is_visible("#live-loads .live-plot > .uplot canvas")
    assert not w.problems, "\n".join(w.problems)




@pytest.mark.parametrize("figure, unit", [("live-efforts", r"^(torque \(N m\)|force \(N\))$"),
                                          ("live-joints", r"^\|?\w+\|? \((N|N m)\)$"),
                                          ("live-p002fig2", r"^(Fˢʰ \(N\)|Mˢʰ \(N m\))$")])
def test_the_efforts_joint_loads_and_paper_plots_are_interactive(paper_site, browser, figure, unit):
    """As the shaking loads' plot: hover shows the time and every curve's value, the axis names
    its unit, a click on a legend entry hides that curve, and printing prints the plot drawn for print;
    for the actuator efforts, the joint loads and a paper's own time series (paper 002's Fig. 2)."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.goto((paper_site / "paper002_decoupling" / "index.html").as_uri(), wait_until="load")
    open_sections(p)
    plot = p.locator(f"#{figure} .live-plot:not([hidden])").first  # a figure of many joints shows one
    p.wait_for_timeout(100)  # opened sections: the plots take their width
    axes = p.eval_on_selector(f"script[data-live='{figure}']", "s => JSON.parse(s.textContent).panels.map(q => q.axis)")
    assert axes and all(re.match(unit, a) for a in axes), axes  # the value axis names its unit (drawn on the canvas)
    shown = hover(p, plot)
    # the time and every stage with a curve in this panel (the joint first shown, the largest load,
    # may be one that only a balanced stage has)
    key = plot.get_attribute("data-quantity")
    has = p.eval_on_selector(f"script[data-live='{figure}']", f"s => JSON.parse(s.textContent).series.map(q => {json.dumps(key)} in q.y)")
    assert len(shown) == len(has) + 1 >= 2 and re.search(r"\d", shown[0]), shown
    assert [bool(re.search(r"\d", v)) for v in shown[1:]] == has, (shown, has)
    pixels = plot.locator("canvas").evaluate("c => c.toDataURL()")
    entry = plot.locator(".u-legend .u-series").nth(1 + has.index(True))
    entry.click()
    assert "u-off" in (entry.get_attribute("class") or "")
    assert plot.locator("canvas").evaluate("c => c.toDataURL()") != pixels  # the curve is gone
    assert_printed(p, figure)
    assert not w.problems, "\n".join(w.problems)


def test_the_player_and_the_plots_share_their_time(server, browser):
    """Scrubbing the player moves every plot's cursor to its time; a click in a plot (not a drag,
    which zooms) moves the paused player to the time clicked."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.goto(server + "scott_russell/index.html", wait_until="load")
    open_sections(p)
    p.click("#player-play")  # pause
    p.eval_on_selector("#player-time", "s => { s.value = '500'; s.dispatchEvent(new Event('input')); }")
    clock = re.match(r"t = (\d+\.\d+) s of (\d+\.\d+) s", p.text_content("#player-clock"))
    t, end = float(clock.group(1)), float(clock.group(2))
    step = end / 100  # the plots keep at least 100 samples: a cursor snaps to the nearest
    plots = p.locator("#live-loads .live-plot, #live-efforts .live-plot, #live-joints .live-plot").all()
    assert len(plots) >= 4
    for plot in plots:
        assert abs(float(plot.evaluate(_CURSOR_TIME)) - t) <= step, plot.get_attribute("data-quantity")
    plot = p.locator("#live-efforts .live-plot").first
    plot.scroll_into_view_if_needed()
    box = plot.locator(".u-over").bounding_box()
    p.mouse.click(box["x"] + box["width"] * 0.2, box["y"] + box["height"] * 0.5)
    clicked = float(plot.evaluate(_CURSOR_TIME))
    assert abs(clicked - 0.2 * end) <= 2 * step
    shown = float(re.match(r"t = (\d+\.\d+)", p.text_content("#player-clock")).group(1))
    assert abs(shown - clicked) <= step and p.get_attribute("#player", "data-playing") == "0"
    assert abs(float(p.locator("#live-loads .live-plot").first.evaluate(_CURSOR_TIME)) - shown) <= step
    # a drag zooms the plot and leaves the player where it is
    p.mouse.move(box["x"] + box["width"] * 0.5, box["y"] + box["height"] * 0.5)
    p.mouse.down()
    p.mouse.move(box["x"] + box["width"] * 0.8, box["y"] + box["height"] * 0.5, steps=5)
    p.mouse.up()
    assert float(re.match(r"t = (\d+\.\d+)", p.text_content("#player-clock")).group(1)) == shown
    assert not w.problems, "\n".join(w.problems)


# ------------------------------------------------------------------------------------------
# The same checks on a site already built (the whole of specs/, say), page by page:
#   balpipe build specs/ -o reports --no-sim
#   python -m pytest tests/report/test_site_browser.py -k built_site --built-site reports


NO_BUILT_SITE = ("no --built-site DIR given: to check every page of a built site, run "
                 "python -m pytest tests/report/test_site_browser.py -k built_site --built-site DIR")


def built_site_dir(config) -> Path | None:
    given = config.getoption("--built-site")
    if given is None:
        return None
    top = Path(given).resolve()
    if not _pages(top):
        raise pytest.UsageError(f"--built-site {given}: no HTML page under {top}")
    return top


def pytest_generate_tests(metafunc):
    """``built_page``: every page of the --built-site; ``built_plot_page``: those with
    interactive plots. Without the option, one skipped case that says how to run them."""
    names = [n for n in ("built_page", "built_plot_page") if n in metafunc.fixturenames]
    if not names:
        return
    top = built_site_dir(metafunc.config)
    if top is None:
        metafunc.parametrize(names[0], [pytest.param(None, marks=pytest.mark.skip(reason=NO_BUILT_SITE))])
        return
    pages = _pages(top)
    if names[0] == "built_plot_page":
        pages = [p for p in pages if "data-live=" in p.read_text(encoding="utf-8")]
    metafunc.parametrize(names[0], pages, ids=[p.relative_to(top).as_posix() for p in pages])


def test_built_site_page_weighs_less_than_2_mb(built_page):
    assert _weight(built_page) < MAX_BYTES


def test_built_site_page_has_no_static_copy_of_a_live_figure(built_page):
    """A live figure is its plot alone (issue 22): no static SVG of the same curves beside it
    (printing prints the plot), a <noscript> line in its place for a reader without JavaScript."""
    html = built_page.read_text(encoding="utf-8")
    assert "static-plot" not in html
    for m in re.finditer(r'<div class="live" id="(live-[^"]+)">(.*?)</div>', html, re.S):
        assert m.group(2).startswith("<noscript>") and "<svg" not in m.group(2), m.group(1)


@pytest.mark.parametrize("width", [400, 1400])
def test_built_site_page_fits_the_window_with_nothing_clipped(built_page, browser, width):
    ctx = layout_context(browser, width)
    try:
        problems = page_problems(ctx, built_page, width)
    finally:
        ctx.close()
    assert not problems, f"{len(problems)} problems at {width} px:\n" + "\n".join(problems[:40])


# for a live plot: [has its quantity] per curve, from the data it was drawn from (a stage without
# the joint of a joint-load panel has no curve there, its legend entry shows a dash); the what-if's
# tried design is drawn by whatif.js from the what-if's maps, with the computed design's quantities
# (its entry in the figure's data is empty)
_CURVES_PRESENT = """el => {
  const id = el.parentElement.id;
  const d = JSON.parse(document.querySelector(`script[data-live='${id}']`).textContent);
  const src = document.getElementById("whatif-data"), w = src ? JSON.parse(src.textContent) : null;
  const drawnFrom = i => (w !== null && w.figure === id && i === w.tried) ? w.computed : i;
  return d.series.map((s, i) => el.dataset.quantity in d.series[drawnFrom(i)].y);
}"""


@pytest.mark.parametrize("width", [400, 1400])
def test_built_site_plots_show_values_on_hover(built_plot_page, browser, width):
    """The first plot of every interactive figure of the page, its sections open, shows the time
    and the value of every curve it draws under the mouse."""
    ctx = layout_context(browser, width)
    w = Watched(ctx)
    p = w.page
    try:
        p.goto(built_plot_page.as_uri(), wait_until="load")
        open_sections(p)
        p.wait_for_timeout(100)
        # plots over time; a Pareto front over its budget has a value only at its designs (its hover
        # is checked at a design in tests/report/test_live_browser.py)
        timed = [h for h in p.locator(".live.live-ready").all()
                 if not p.eval_on_selector(f"script[data-live='{h.get_attribute('id')}']", "s => 'x' in JSON.parse(s.textContent)")]
        plots = [h.locator(".live-plot:not([hidden])").first for h in timed]
        assert plots, "no interactive plot drawn"
        for plot in plots:
            shown = hover(p, plot, min_width=width // 4)
            present = plot.evaluate(_CURVES_PRESENT)
            assert len(shown) == 1 + len(present) and any(present), plot.get_attribute("data-quantity")
            valued = [bool(re.search(r"\d", v)) for v in shown]
            assert valued == [True] + present, (plot.get_attribute("data-quantity"), shown)
    finally:
        ctx.close()
    assert not w.problems, "\n".join(w.problems)


_SECTIONS = """() => [...document.querySelectorAll('details.section')].map(d =>
    [d.querySelector('summary').textContent.trim(), d.open])"""
_SHOWN = """id => { const el = document.getElementById(id); const d = el && el.closest('details.section');
    const r = el && el.getBoundingClientRect();
    return !!d && d.open && r.top >= -1 && r.top < innerHeight; }"""


@pytest.mark.parametrize("width", [400, 1400])
def test_the_papers_figures_and_the_costs_are_open_and_links_open_their_section(server, browser, width):
    """Open at load: the paper's figures, "Published vs computed" and the actuators' costs, beside
    the stage table and the shaking loads; the other sections folded. A deep link loaded directly,
    a Contents entry clicked and a change of the fragment open the section of their target and
    scroll to it; "open all" and "close all" act on every section."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    url = server + "scott_russell/index.html"
    p.goto(url, wait_until="load")
    state = dict(p.evaluate(_SECTIONS))
    # the paper's figures ("Fig. N of paper ...") open by their titles: tests/report/test_pages.py
    must_open = [t for t in state if re.match(r"Figs?\.\s*\d", t)] + ["Balancing stages", "What balancing costs the actuators", "Shaking force and shaking moment"]
    must_open += [t for t in state if t == "Published vs computed"]
    assert all(state[t] for t in must_open), {t: state[t] for t in must_open}
    folded = [t for t, is_open in state.items() if not is_open]
    assert "Checks" in folded and "Inputs" in folded, state

    # a deep link loaded directly: its folded section opens and its heading is in the window
    p.goto(server + "osc/index.html", wait_until="load")  # another page first: a real navigation
    p.goto(url + "#checks", wait_until="load")
    p.wait_for_function(_SHOWN, arg="checks")
    # a Contents entry clicked, from the top of a fresh load
    p.goto(url, wait_until="load")
    assert not p.evaluate("() => document.getElementById('inputs').closest('details').open")
    p.click('nav.toc a[href="#inputs"]')
    p.wait_for_function(_SHOWN, arg="inputs")
    # the fragment changed by hand (hashchange) opens a folded section too
    assert not p.evaluate("() => document.getElementById('joint-loads').closest('details').open")
    p.evaluate("location.hash = '#joint-loads'")
    p.wait_for_function(_SHOWN, arg="joint-loads")

    # open all, close all
    p.click("nav.toc button[data-sections=open]")
    p.wait_for_function("[...document.querySelectorAll('details.section')].every(d => d.open)")
    p.click("nav.toc button[data-sections=close]")
    p.wait_for_function("[...document.querySelectorAll('details.section')].every(d => !d.open)")
    assert p.text_content("nav.toc button[data-sections=open]") == "open all"
    assert p.text_content("nav.toc button[data-sections=close]") == "close all"
    assert not w.problems, "\n".join(w.problems)


@pytest.fixture(scope="module")
def compare_site(tmp_path_factory) -> Path:
    """Two designs of one mechanism (the offset slider-crank's counterweights and its partial
    optimum) and a paper spec, built without simulation."""
    out = tmp_path_factory.mktemp("compare") / "site"
    specs = Path(__file__).resolve().parents[2] / "specs"
    names = ("offset_slider_crank.yaml", "partial_offset_slider_crank.yaml", "paper000_rpr3_scott_russell.yaml")
    outcomes = build([str(specs / s) for s in names], Options(out=out, simulate=False))
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    return out


def _order(page) -> list[str]:
    return page.eval_on_selector_all("#studies tbody.entry", "els => els.map(e => e.dataset.spec)")


@pytest.mark.parametrize("width", [400, 1400])
def test_index_sorts_filters_by_verdict_and_compares_designs_of_one_mechanism(compare_site, browser, width):
    """Every column of the index sorts (again: the other way) and the order is kept in the
    address; the verdict filter; a row's paper links to its one citation; the designs of one
    mechanism are side by side, sortable, with the added mass relative to the moving mass."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    p.goto((compare_site / "index.html").as_uri(), wait_until="load")
    built = _order(p)
    force = {s: float(json.loads((compare_site / s / "results.json").read_text())["verdict"]["motions"][0]["force"][1])
             for s in built}
    p.click('#studies button[data-sort="force"]')
    assert _order(p) == sorted(built, key=force.get)
    assert "sort=force" in p.evaluate("location.hash")
    assert p.get_attribute('#studies th:has(button[data-sort="force"])', "aria-sort") == "ascending"
    p.click('#studies button[data-sort="force"]')
    assert _order(p) == sorted(built, key=force.get, reverse=True)
    # a shared address restores the order and the filter
    levels = {s: json.loads((compare_site / s / "results.json").read_text())["verdict"]["verdict"] for s in built}
    level = levels["paper000_rpr3_scott_russell"]
    p.goto((compare_site / "index.html").as_uri() + f"#verdict={level}&sort=-title", wait_until="load")
    p.reload(wait_until="load")
    shown = visible_specs(p)
    assert len(shown) == sum(v == level for v in levels.values()) and p.eval_on_selector("#f-verdict", "s => s.value") == level
    titles = p.eval_on_selector_all("#studies tbody.entry", "els => els.map(e => e.dataset.sortTitle)")
    assert titles == sorted(titles, reverse=True)
    # the paper's citation once, above; the row links to it and opens it
    p.select_option("#f-verdict", "")
    with_paper = [s for s in built if json.loads((compare_site / s / "results.json").read_text())["paper"]]
    links = p.eval_on_selector_all("a.cite", "els => els.map(a => a.getAttribute('href'))")
    assert links == ["#paper-000"] * len(with_paper) and with_paper
    assert p.locator("li#paper-000").count() == 1 and not p.is_visible("#paper-000")
    p.locator("a.cite").first.click()
    assert p.is_visible("#paper-000")
    # the designs of the slider-crank side by side; no table for the Scott-Russell's one spec
    tables = p.locator("#compared table.compare")
    assert tables.count() == 1
    rows = lambda: tables.first.evaluate("t => [...t.tBodies[0].rows].map(r => r.cells[0].textContent)")
    assert len(rows()) == 2
    rel = tables.first.evaluate("t => [...t.tBodies[0].rows].map(r => Number(r.cells[4].dataset.sort))")
    moving = json.loads((compare_site / "offset_slider_crank" / "results.json").read_text())["moving_mass"]
    added = {s: json.loads((compare_site / s / "results.json").read_text())["verdict"]["motions"][0]["costs"]["added_mass"]
             for s in ("offset_slider_crank", "partial_offset_slider_crank")}
    assert sorted(rel) == pytest.approx(sorted(a / moving for a in added.values()), rel=1e-12)
    before = rows()
    tables.first.locator('button[data-col="4"]').click()
    first = rows()
    tables.first.locator('button[data-col="4"]').click()
    assert rows() == first[::-1] and sorted(first) == sorted(before)
    assert not w.problems, "\n".join(w.problems)


def test_wide_screens_keep_the_contents_beside_the_page(paper_site, browser):
    """At 1700 px the Contents stay in the left margin while the page scrolls, never over the
    page; a side entry opens its folded section and is marked as the section in view; at
    1400 px there is no room and no side Contents."""
    page = paper_site / "paper000_rpr3_scott_russell" / "index.html"
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1700, "height": 900})
    p.goto(page.as_uri(), wait_until="load")
    side = p.locator("nav.toc-side")
    assert side.is_visible()
    entries = side.locator("a").evaluate_all("els => els.map(a => a.textContent)")
    assert entries == p.locator("nav.toc a").evaluate_all("els => els.map(a => a.textContent)") and entries
    box, main = side.bounding_box(), p.locator("main").bounding_box()
    assert box["x"] + box["width"] <= main["x"] + 1
    folded = p.eval_on_selector_all(
        "nav.toc-side a", "els => els.filter(a => { const t = document.getElementById(a.getAttribute('href').slice(1));"
        " const d = t && t.closest('details'); return d && !d.open; }).map(a => a.getAttribute('href'))")
    assert folded, "no folded section to open"
    link = side.locator(f'a[href="{folded[-1]}"]')
    link.click()
    target = p.locator(folded[-1])
    assert target.evaluate("t => t.closest('details').open") and target.is_visible()
    p.wait_for_function(f"document.querySelector('nav.toc-side a[href=\"{folded[-1]}\"]').classList.contains('current')")
    assert side.bounding_box()["y"] == box["y"]  # it stayed where it was while the page scrolled
    p.set_viewport_size({"width": 1400, "height": 900})
    assert not side.is_visible()
    assert not w.problems, "\n".join(w.problems)


@pytest.mark.parametrize("width", [1400, 400])
def test_the_mechanism_moves_with_its_shaking_loads_in_table_order(paper_site, studies, browser, width):
    """Every page's mechanism drawings move: one panel per stage in the stage table's order, at
    one scale, paused at load; the shaking force and moment at each panel's time are the engine's
    (to the 4 digits shown); a click in a plot (balpipe:seek) moves it; at 400 px one readable
    column (panels at their own size, not shrunk)."""
    study = studies("custom_four_bar_balancing.yaml")
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    p.goto((paper_site / "custom_four_bar_balancing" / "index.html").as_uri(), wait_until="load")
    p.click("#the-mechanism")
    cv = p.locator("#mechanism-player")
    cv.scroll_into_view_if_needed()
    assert cv.get_attribute("data-playing") == "0"
    table = p.eval_on_selector_all("details:has(#balancing-stages) table tr td:first-child strong",
                                   "els => els.map(e => e.textContent.trim())")
    labels = json.loads(cv.get_attribute("data-stages"))
    assert labels == [s.stage.label for s in study.stages if s.stage.group == study.stages[0].stage.group]
    assert [t for t in table if t in labels][:len(labels)] == labels
    cols = int(cv.get_attribute("data-columns"))
    box = cv.bounding_box()
    assert (cols == 1 and box["width"] >= 299) if width == 400 else cols == min(4, len(labels))
    p.eval_on_selector("#mechanism-player-time", "s => { s.value = '1000'; s.dispatchEvent(new Event('input')); }")
    shown = cv.get_attribute("data-loads").split(" | ")
    fmax = max(float(np.max(np.hypot(*s.analysis.force.T))) for s in study.stages if s.stage.label in labels)
    for text, s in zip(shown, [next(x for x in study.stages if x.stage.label == lab) for lab in labels]):
        m = re.fullmatch(r"\|F\| (\S+) N, M (\S+) N m", text)
        assert m, text
        f = float(np.hypot(*s.analysis.force[-1]))
        assert float(m.group(1)) == (pytest.approx(f, rel=1e-3) if f > 1e-9 * fmax else 0.0), (s.stage.label, text)
    pixels = cv.evaluate("c => c.toDataURL()")
    t_end = p.text_content("#mechanism-player-clock")
    p.evaluate("document.dispatchEvent(new CustomEvent('balpipe:seek', {detail: {time: 0.2}}))")
    assert p.text_content("#mechanism-player-clock").startswith("t = 0.200 s") and cv.evaluate("c => c.toDataURL()") != pixels
    assert t_end != p.text_content("#mechanism-player-clock")
# --- one style per stage, the simulation's toggle, lazy figures (templates/live_plots.js) ---

_KEY = """() => Object.fromEntries([...document.querySelectorAll('#style-legend .stage-key')].map(k => {
  const s = k.querySelector('.swatch');
  return [k.dataset.stage, [s.dataset.stroke, s.dataset.dash, s.dataset.marker, !!s.querySelector('svg line')]]; }))"""
_LEGENDS = """() => [...document.querySelectorAll('.live.live-ready')].map(h => [h.id,
  [...h.querySelectorAll('.live-plot:not([hidden]) .u-legend')].slice(0, 1).flatMap(l => [...l.querySelectorAll('.u-series')])
    .filter(r => r.querySelector('.swatch'))
    .map(r => { const s = r.querySelector('.swatch');
      return [r.querySelector('.u-label').textContent, s.dataset.stroke, s.dataset.dash, s.dataset.marker,
              r.classList.contains('sim'), !!s.querySelector('svg line'), r.querySelector('th').title]; })])"""


@pytest.mark.parametrize("width", [400, 1400])
def test_legend_swatches_show_each_stages_dash_and_marker_as_the_key(site, paper_site, browser, width):
    """Every stage's entry in every legend of a page (its short name) shows the swatch of the
    page's key: the same colour, dashes and marker, drawn (an SVG line); the loads' legend names
    every stage of the key; a short name's long label is its tooltip."""
    ctx = layout_context(browser, width)
    w = Watched(ctx)
    p = w.page
    checked = 0
    try:
        for page_file in [paper_site / slug.removesuffix(".yaml") / "index.html" for slug in PAPER_SPECS] + \
                         [site / SUBFOLDER / "scott_russell" / "index.html"]:
            p.goto(page_file.as_uri(), wait_until="load")
            open_sections(p)
            key = p.evaluate(_KEY)
            assert key and all(drawn for *_, drawn in key.values()), (page_file, key)
            figures = dict(p.evaluate(_LEGENDS))
            assert set(key) <= {row[0] for row in figures["live-loads"]}, (page_file, key, figures["live-loads"])
            for fig, rows in figures.items():
                for name, stroke, dash, marker, sim, drawn, title in rows:
                    assert drawn, (fig, name)
                    if name in key and not sim:
                        assert [stroke, dash, marker] == key[name][:3], (page_file, fig, name, key[name])
                        checked += 1
            long = p.evaluate("() => [...document.querySelectorAll('#style-legend .stage-key')].map(k => [k.dataset.stage, k.title])")
            for fig, rows in figures.items():
                for name, *_, title in rows:
                    for short, label in long:
                        if name == short and label != short:
                            assert title == label, (fig, name, title, label)
    finally:
        ctx.close()
    assert checked > 20
    assert not w.problems, "\n".join(w.problems)


@pytest.mark.parametrize("width", [400, 1400])
def test_the_simulated_curves_are_hidden_until_their_toggle_shows_them(server, browser, width):
    """The shaking loads' pymunk curves are off at load (their legend rows off, the stages' on);
    the figure's one toggle shows them in every panel, and hides them again."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    p.goto(server + "scott_russell/index.html", wait_until="load")
    rows = """() => [...document.querySelectorAll('#live-loads .live-plot')].map(el =>
        [...el.querySelectorAll('.u-legend .u-series')].filter(r => r.querySelector('.swatch'))
          .map(r => [r.classList.contains('sim'), r.classList.contains('u-off')]))"""
    shown = p.evaluate(rows)
    assert len(shown) == 4 and all(any(sim for sim, _ in panel) for panel in shown), shown
    assert all(off == sim for panel in shown for sim, off in panel), shown
    assert not p.locator("#live-loads .u-series.sim").first.is_visible()  # nor listed
    toggle = p.locator("#live-loads .live-sim input")
    assert toggle.count() == 1 and not toggle.is_checked()
    pixels = p.locator("#live-loads .live-plot canvas").first.evaluate("c => c.toDataURL()")
    toggle.check()
    assert all(not off for panel in p.evaluate(rows) for _, off in panel)
    assert p.locator("#live-loads .u-series.sim").first.is_visible()
    assert p.locator("#live-loads .live-plot canvas").first.evaluate("c => c.toDataURL()") != pixels  # drawn
    toggle.uncheck()
    assert all(off == sim for panel in p.evaluate(rows) for sim, off in panel)
    assert not w.problems, "\n".join(w.problems)


@pytest.mark.parametrize("width", [400, 1400])
def test_a_folded_sections_figures_are_built_when_it_opens(paper_site, browser, width):
    """At load only the figures of open sections are drawn; a folded section's figure has no
    plot until the section opens (a click on its summary), then it is drawn at its width."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    p.goto((paper_site / "paper002_decoupling" / "index.html").as_uri(), wait_until="load")
    state = p.evaluate("""() => [...document.querySelectorAll('script[data-live]')].map(s => {
        const h = document.getElementById(s.dataset.live);
        return [h.id, !!h.closest('details:not([open])'), h.querySelectorAll('.live-plot').length]; })""")
    folded = [h for h, closed, n in state if closed]
    assert folded and all(n == 0 for _, closed, n in state if closed), state
    assert all(n > 0 for _, closed, n in state if not closed), state
    target = folded[0]
    p.locator(f"details.section:has(#{target}) > summary").first.click()
    p.wait_for_function(f"document.querySelectorAll('#{target} .live-plot').length > 0")
    p.wait_for_timeout(100)
    box = p.locator(f"#{target} .live-plot:not([hidden]) .u-over").first.bounding_box()
    assert box and box["width"] > width / 3, box
    still = p.evaluate("""() => [...document.querySelectorAll('script[data-live]')].map(s => document.getElementById(s.dataset.live))
        .filter(h => h.closest('details:not([open])')).map(h => h.querySelectorAll('.live-plot').length)""")
    assert all(n == 0 for n in still), still
    assert not w.problems, "\n".join(w.problems)


_UNIT_IN_NAME = re.compile(r"\([^()]+\)$")


@pytest.mark.parametrize("width", [400, 1400])
def test_every_figure_offers_its_data_as_csv_with_units_and_itself_as_png(server, site, browser, width):
    """Under every interactive figure: a link to its data (a CSV beside the page whose every
    column name ends in its unit) and, once drawn, a button that downloads the figure as a PNG."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    p.goto(server + "scott_russell/index.html", wait_until="load")
    open_sections(p)
    figures = p.evaluate("() => [...document.querySelectorAll('script[data-live]')].map(s => s.dataset.live)")
    links = dict(p.evaluate("""() => [...document.querySelectorAll('p.downloads[data-for]')].map(b =>
        [b.dataset.for, b.querySelector('a[download]').getAttribute('href')])"""))
    assert figures and sorted(links) == sorted(figures), (figures, links)
    for fig, href in links.items():
        text = (site / SUBFOLDER / "scott_russell" / href).read_text(encoding="utf-8")
        head = next(iter(csv.reader(io.StringIO(text))))
        assert len(head) >= 2 and all(_UNIT_IN_NAME.search(h) for h in head), (href, head)
        assert text.count("\n") >= 2, href  # a header and a row at least (a history of one commit)
    button = p.locator('p.downloads[data-for="live-loads"] button.png')
    button.scroll_into_view_if_needed()
    with p.expect_download() as got:
        button.click()
    d = got.value
    assert d.suggested_filename == "figure-loads.png"
    data = Path(d.path()).read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) > 5000
    assert not w.problems, "\n".join(w.problems)


@pytest.mark.parametrize("width", [400, 1400])
def test_every_static_figure_downloads_as_svg_and_png(server, browser, width):
    """Under every figure drawn as an inline SVG (the mechanism drawings), a button saves that
    SVG as a file (a standalone SVG document) and one saves it as a PNG."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": width, "height": 900})
    p.goto(server + "osc/index.html", wait_until="load")
    open_sections(p)
    bars = p.locator("p.downloads.static")
    assert bars.count() >= 2  # a drawing per stage
    assert p.evaluate("() => [...document.querySelectorAll('p.downloads.static')].every(b => b.closest('figure').querySelector(':scope > svg, svg'))")
    bar = bars.first
    bar.scroll_into_view_if_needed()
    with p.expect_download() as got:
        bar.locator("button.svg").click()
    text = Path(got.value.path()).read_text(encoding="utf-8")
    assert got.value.suggested_filename.endswith(".svg") and 'xmlns="http://www.w3.org/2000/svg"' in text and text.rstrip().endswith("</svg>")
    with p.expect_download() as got:
        bar.locator("button.png").click()
    assert got.value.suggested_filename.endswith(".png") and Path(got.value.path()).read_bytes().startswith(b"\x89PNG")
    assert not w.problems, "\n".join(w.problems)


def test_a_spec_named_in_a_description_links_to_its_page_when_the_site_has_it(compare_site, browser):
    """partial_offset_slider_crank.yaml's description names offset_slider_crank.yaml, built on
    this site: the name is a link to that page, titled with its study; a name the site does not
    hold stays text (no dead link), and the page's own text is otherwise unchanged."""
    w = Watched(browser)
    p = w.page
    page = compare_site / "partial_offset_slider_crank" / "index.html"
    raw = page.read_text(encoding="utf-8")
    assert "offset_slider_crank.yaml" in raw.split('<p class="description">')[1].split("</p>")[0]
    p.goto(page.as_uri(), wait_until="load")
    links = p.eval_on_selector_all("p.description a", "els => els.map(a => [a.getAttribute('href'), a.textContent, a.title])")
    assert links and all(h == "../offset_slider_crank/index.html" and t == "offset_slider_crank.yaml" and title
                         for h, t, title in links), links
    before = p.text_content("p.description")
    p.click("p.description a")
    p.wait_for_url("**/offset_slider_crank/index.html", wait_until="load")
    # the Scott-Russell 3-RPR names its corrected spec, which this site does not hold: text only
    p.goto((compare_site / "paper000_rpr3_scott_russell" / "index.html").as_uri(), wait_until="load")
    assert p.eval_on_selector_all("p.description a", "els => els.length") == 0
    assert "paper000_rpr3_scott_russell_corrected.yaml" in p.text_content("p.description")
    assert "offset_slider_crank.yaml" in before and not w.problems, "\n".join(w.problems)
