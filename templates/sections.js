// The folded sections of a long page (report/sections.py): a Contents entry, a deep link
// (#heading-id, on load and on every change of the fragment) opens the <details> that holds its
// target and scrolls to it; "open all" / "close all" beside the Contents act on every section.
(function () {
  "use strict";
  const sections = Array.from(document.querySelectorAll("details.section"));
  if (!sections.length) return;
  function target(hash) {
    if (!hash || hash.length < 2) return null;
    let id = hash.slice(1);
    try { id = decodeURIComponent(id); } catch (e) { /* a malformed escape: the id as written */ }
    return document.getElementById(id);
  }
  // open every <details> around el, and the one whose summary holds el (a section's heading)
  function reveal(el) {
    let opened = false;
    for (let n = el; n; n = n.parentElement) {
      const d = n.tagName === "SUMMARY" ? n.parentElement : n;
      if (d && d.tagName === "DETAILS" && !d.open) { d.open = true; opened = true; }
    }
    return opened;
  }
  function go(hash, scroll) {
    const el = target(hash);
    if (!el) return;
    const opened = reveal(el);
    if (scroll || opened) el.scrollIntoView();
  }
  // a click on a link into this page opens its target's section before the browser scrolls to it
  document.addEventListener("click", ev => {
    const a = ev.target.closest && ev.target.closest('a[href^="#"]');
    if (a) reveal(target(a.getAttribute("href")) || document.body);
  });
  addEventListener("hashchange", () => go(location.hash, true));
  go(location.hash, false);
  addEventListener("load", () => go(location.hash, false));
  const toc = document.querySelector("nav.toc");
  if (toc) {
    const bar = document.createElement("p");
    bar.className = "toc-all";
    for (const [word, state] of [["open all", true], ["close all", false]]) {
      const b = document.createElement("button");
      b.type = "button";
      b.textContent = word;
      b.dataset.sections = state ? "open" : "close";
      b.addEventListener("click", () => sections.forEach(d => { d.open = state; }));
      bar.appendChild(b);
    }
    toc.appendChild(bar);
  }
})();
