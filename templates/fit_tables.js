// Tables that do not fit their column (a narrow window, many stages) are shown one row per card,
// each value named by its column's heading, instead of scrolling or clipping (style.css: table.stack).
(function () {
  "use strict";
  function label(t) {
    const rows = Array.from(t.rows);
    const head = rows.find(r => r.cells.length > 1 && Array.from(r.cells).every(c => c.tagName === "TH"));
    if (!head) return;
    const names = [];
    for (const c of head.cells) for (let k = 0; k < (c.colSpan || 1); k++) names.push(c.textContent.trim());
    head.classList.add("head");
    for (const r of rows) {
      if (r === head || r.parentElement.tagName === "THEAD") continue;
      let i = 0;
      for (const c of r.cells) {
        if (c.tagName === "TD" && !c.dataset.label && names[i] && (c.colSpan || 1) === 1) c.dataset.label = names[i];
        i += c.colSpan || 1;
      }
    }
  }
  function fit() {
    const tables = Array.from(document.querySelectorAll("main table:not(.u-legend)"));
    tables.forEach(t => t.classList.remove("stack"));
    // outermost first: a stacked table gives its inner tables the room to fit
    tables.forEach(t => {
      if (t.offsetParent === null) return;  // in a closed section: measured when it opens
      const room = t.parentElement.clientWidth;
      if (t.scrollWidth > room + 1 || t.getBoundingClientRect().right > document.documentElement.clientWidth + 1) t.classList.add("stack");
    });
  }
  document.querySelectorAll("main table:not(.u-legend)").forEach(label);
  fit();
  let timer = 0;
  addEventListener("resize", () => { clearTimeout(timer); timer = setTimeout(fit, 100); });
  // printing shows everything: the collapsed sections open, the tables as tables
  addEventListener("beforeprint", () => {
    document.querySelectorAll("details.section").forEach(d => { if (!d.open) { d.open = true; d.dataset.printed = "1"; } });
    document.querySelectorAll("main table.stack").forEach(t => t.classList.remove("stack"));
  });
  addEventListener("afterprint", () => {
    document.querySelectorAll("details.section[data-printed]").forEach(d => { d.open = false; delete d.dataset.printed; });
    fit();
  });
  // a section opened later holds tables that could not be measured while closed
  document.querySelectorAll("details").forEach(d => d.addEventListener("toggle", fit));
})();
