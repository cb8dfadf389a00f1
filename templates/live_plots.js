// Interactive plots (report/live_plots.py): uPlot draws the curves of every
// <script type="application/json" data-live="ID"> into the element #ID, a plot per panel: hover for
// values, drag to zoom (double-click resets), click a legend entry to hide a curve. Linked to the
// player both ways: the player announces its time ("balpipe:time" on document) and every plot's
// cursor follows it; a click (not a drag) in a plot asks the player to go to that time
// ("balpipe:seek"). Pages without a player simply have no one announcing or listening.
(function () {
  "use strict";
  if (typeof uPlot === "undefined") return;
  const HEIGHT = 240;
  function fmt(v) {
    if (v == null) return "—";
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e6) ? v.toExponential(3) : (+v.toPrecision(4)).toString();
  }
  // kinematic warnings (time, label): dotted vertical lines, as in the static figure
  function marksPlugin(marks) {
    return { hooks: { draw: u => {
      const c = u.ctx, top = u.bbox.top, h = u.bbox.height, r = devicePixelRatio || 1;
      c.save();
      c.strokeStyle = "#666"; c.fillStyle = "#444"; c.lineWidth = r; c.setLineDash([2 * r, 2 * r]);
      c.font = (10 * r) + "px sans-serif"; c.textAlign = "right";
      for (const [t, text] of marks) {
        const x = Math.round(u.valToPos(t, "x", true));
        if (x < u.bbox.left || x > u.bbox.left + u.bbox.width) continue;
        c.beginPath(); c.moveTo(x, top); c.lineTo(x, top + h); c.stroke();
        c.save(); c.translate(x - 3 * r, top + 4 * r); c.rotate(-Math.PI / 2); c.fillText(text, 0, 0); c.restore();
      }
      c.restore();
    } } };
  }
  // the legend's rows back in the stages' order (uPlot lists its series in drawing order);
  // moving a row keeps its click handler and the cells that show the hovered values
  function legendInStageOrder(u, order) {
    const rows = u.root.querySelectorAll(".u-legend .u-series");  // rows[0]: the time
    if (rows.length !== order.length + 1) return;
    const parent = rows[0].parentNode;
    for (let i = 0; i < order.length; i++) parent.appendChild(rows[1 + order.indexOf(i)]);
  }
  // a figure of many panels (a joint per panel): a selector above shows one panel at a time
  // (first d.choose, the largest load) or every panel; a plot drawn hidden takes its width when shown
  function chooser(host, d, f) {
    const box = document.createElement("label");
    box.className = "live-choose";
    box.textContent = "Show ";
    const sel = document.createElement("select");
    d.panels.forEach((p, i) => sel.add(new Option(p.title + (i === d.choose ? " (largest load)" : ""), String(i))));
    sel.add(new Option("every joint (" + d.panels.length + " panels)", "all"));
    sel.value = String(d.choose);
    box.appendChild(sel);
    host.insertBefore(box, host.firstChild);
    function show() {
      f.plots.forEach((u, i) => {
        const el = u.root.parentNode;
        el.hidden = sel.value !== "all" && sel.value !== String(i);
        if (!el.hidden) u.setSize({ width: Math.max(240, el.clientWidth), height: HEIGHT });
      });
      host.dataset.shown = sel.value;
      follow(f);
    }
    sel.addEventListener("change", show);
    show();
  }
  const figures = [];  // {host, plots, hovering}
  let playerTime = null;
  function follow(f) {
    if (playerTime == null || f.hovering || f.timeless || f.host.offsetParent === null) return;  // hidden: skip
    f.plots.forEach(u => u.setCursor({ left: u.valToPos(playerTime, "x"), top: 20 }));
  }
  document.querySelectorAll("script[type='application/json'][data-live]").forEach(src => {
    const host = document.getElementById(src.dataset.live);
    if (!host) return;
    const d = JSON.parse(src.textContent);
    if (!d.panels.length) return;
    const f = { host: host, plots: [], hovering: false, timeless: !!d.x };
    if (d.panels.length > 2) host.classList.add("live-grid");  // small multiples: as many columns as fit
    const width = el => Math.max(240, el.clientWidth);
    // drawn in d.draw's order (wide lines first, under the thin ones), listed in the stages' order
    const order = d.draw || d.series.map((s, i) => i);
    const drawn = order.map(i => d.series[i]);
    for (const p of d.panels) {
      const el = document.createElement("div");
      el.className = "live-plot";
      el.dataset.quantity = p.key;
      host.appendChild(el);
      // over time, or (d.x) over another quantity: a front's budget, each value a design marked
      const series = [{ label: d.x || "t (s)", value: (u, v) => fmt(v) }].concat(drawn.map(s => Object.assign({
        label: s.label, stroke: s.stroke, dash: s.dash, width: s.width, value: (u, v) => fmt(v),
      }, d.x ? { spanGaps: true, points: { show: true, size: s.points ? 10 : 5, width: 1.5, fill: "#fff" } } : {},
         s.points ? { paths: () => null } : {})));
      const opts = {
        title: p.title, width: width(el), height: HEIGHT,
        scales: { x: { time: false } },
        axes: [{ label: d.x || "time (s)" }, { label: p.axis, size: 64 }],
        series: series,
        cursor: { sync: { key: src.dataset.live } },
        plugins: d.marks.length ? [marksPlugin(d.marks)] : [],
      };
      const u = new uPlot(opts, [d.t].concat(drawn.map(s => s.y[p.key] || d.t.map(() => null))), el);
      legendInStageOrder(u, order);
      f.plots.push(u);
      if (d.x) continue;  // not over time: not linked to the player
      u.over.addEventListener("mouseenter", () => { f.hovering = true; });
      u.over.addEventListener("mouseleave", () => { f.hovering = false; follow(f); });
      // a click, not a drag to zoom, sends the player to the time under the cursor
      let down = null;
      u.over.addEventListener("mousedown", e => { down = [e.clientX, e.clientY]; });
      u.over.addEventListener("mouseup", e => {
        const still = down && Math.abs(e.clientX - down[0]) < 4 && Math.abs(e.clientY - down[1]) < 4;
        down = null;
        if (!still) return;
        const t = u.posToVal(e.clientX - u.over.getBoundingClientRect().left, "x");
        if (isFinite(t)) document.dispatchEvent(new CustomEvent("balpipe:seek", { detail: { time: t } }));
      });
    }
    if (d.choose != null) chooser(host, d, f);
    host.classList.add("live-ready");
    if (!d.x) figures.push(f);
    // follow the host's width (the window, or a collapsed section opened): resize after the
    // observer's callback, never inside it
    let last = host.clientWidth, pending = 0;
    new ResizeObserver(() => {
      if (host.clientWidth === last || host.clientWidth === 0) return;
      last = host.clientWidth;
      cancelAnimationFrame(pending);
      pending = requestAnimationFrame(() => { f.plots.forEach(u => u.setSize({ width: width(u.root.parentNode), height: HEIGHT })); follow(f); });
    }).observe(host);
  });
  document.addEventListener("balpipe:time", e => {
    playerTime = e.detail.time;
    figures.forEach(follow);
  });
})();
