// Interactive plots (report/live_plots.py): uPlot draws the curves of every
// <script type="application/json" data-live="ID"> into the element #ID, a plot per panel: hover for
// values, drag to zoom (double-click resets), click a legend entry to hide a curve. Linked to the
// player both ways: the player announces its time ("balpipe:time" on document) and every plot's
// cursor follows it; a click (not a drag) in a plot asks the player to go to that time
// ("balpipe:seek"). Pages without a player simply have no one announcing or listening.
// Printing prints these plots: on "beforeprint" (the print dialog, and Chromium's page.pdf) or when
// the print media query starts to match (Chromium's emulated print media, the print layout), every
// panel is drawn once more, for the paper: PRINT_WIDTH wide (half of it a panel in a figure of
// small multiples, two a row), at PRINT_RATIO device pixels per CSS pixel, stretched to the
// printed column by style.css; every panel of a joint selector; removed again after printing.
(function () {
  "use strict";
  if (typeof uPlot === "undefined") return;
  const HEIGHT = 240;
  const PRINT_WIDTH = 700, PRINT_GAP = 16, PRINT_RATIO = 3;  // CSS px: an A4 or Letter page's column
  // numbers as the pages write them (balpipe.display.numbers): fixed-point decimals to 4
  // significant digits, never "1.2e-5"; a magnitude below a millionth or from a thousand million
  // as a written-out power of ten (2.8×10⁻¹¹); a value within the panel's round-off floor
  // (draw/live.py) reads as the tables write it
  const SUPERSCRIPT = { "-": "⁻", "0": "⁰", "1": "¹", "2": "²", "3": "³", "4": "⁴", "5": "⁵", "6": "⁶", "7": "⁷", "8": "⁸", "9": "⁹" };
  function powerOfTen(v, digits) {
    const parts = v.toExponential(Math.max(0, digits - 1)).split("e");
    const m = parts[0].indexOf(".") >= 0 ? parts[0].replace(/0+$/, "").replace(/\.$/, "") : parts[0];
    return m + "×10" + String(parseInt(parts[1], 10)).replace(/[-0-9]/g, c => SUPERSCRIPT[c]);
  }
  function fmt(v, floor) {
    if (v == null) return "—";
    const a = Math.abs(v);
    if (floor && a <= floor) return "0 (< tolerance)";
    return a !== 0 && (a < 1e-6 || a >= 1e9) ? powerOfTen(v, 4) : (+v.toPrecision(4)).toString();
  }
  // an axis's tick labels: uPlot's own (at most 3 decimals: a residual of 1e-5 read "0"), in
  // exponent form when the ticks are all below 1e-3 or from 1e6; on a log axis (p.log) the powers
  // of ten only, every k-th of them so that labels stay LOG_LABEL_PX apart (a residual over 15
  // decades had a label every 9 px, overprinted). The plotting area's height is the plot's less
  // its title and time axis (the canvas is not sized yet when uPlot first asks for labels)
  const num = uPlot.fmtNum || (v => String(v));
  const LOG_LABEL_PX = 14, TITLE_AND_AXIS_PX = 100;
  function ticks(log) {
    return (u, vals) => {
      const big = Math.max(0, ...vals.map(v => Math.abs(v || 0)));
      const exp = big !== 0 && (big < 1e-3 || big >= 1e6);
      const sc = u.scales.y || {};
      const decades = log && sc.min > 0 && sc.max > sc.min ? Math.log10(sc.max / sc.min) : 1;
      const every = Math.max(1, Math.ceil(decades * LOG_LABEL_PX / Math.max(u.height - TITLE_AND_AXIS_PX, 40)));
      return vals.map(v => {
        if (v == null) return "";
        if (!log) return exp && v !== 0 ? powerOfTen(v, 2) : num(v);
        const e = Math.round(Math.log10(v));
        if (Math.abs(Math.log10(v) - e) > 1e-6 || e % every !== 0) return "";
        return Math.abs(e) >= 3 ? powerOfTen(v, 1) : num(v);
      });
    };
  }
  // a plot at least as tall as its value axis's label needs: uPlot centres the label along the
  // plotting area and the canvas clips it ("peak actuator effort (N m or N)" lost its unit in a
  // 240 px plot); the label is measured in the font it is drawn in
  const LABEL_FONT = 'bold 12px system-ui,-apple-system,"Segoe UI",Roboto,"Helvetica Neue",Arial,sans-serif';
  let measurer = null;
  function plotHeight(label) {
    measurer = measurer || document.createElement("canvas").getContext("2d");
    measurer.font = LABEL_FONT;
    return Math.max(HEIGHT, Math.ceil(measurer.measureText(label || "").width) + TITLE_AND_AXIS_PX);
  }
  // the canvas's device pixels per CSS pixel: the screen's, or PRINT_RATIO in a plot drawn for print
  const ratio = u => u.ctx.canvas.width / u.width || 1;
  // kinematic warnings (time, label): dotted vertical lines, labelled along them
  function marksPlugin(marks) {
    return { hooks: { draw: u => {
      const c = u.ctx, top = u.bbox.top, h = u.bbox.height, r = ratio(u);
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
  // a stage's markers (draw/live.py): matplotlib's symbol, unfilled, at every `every` sample from
  // `start` (staggered per stage, so that coinciding curves stay apart), 4.5 pt as the paper figures
  const SHAPES = {
    o: [], s: [[-1, -1], [1, -1], [1, 1], [-1, 1]], D: [[0, -1.25], [1.25, 0], [0, 1.25], [-1.25, 0]],
    "^": [[0, -1.2], [1.1, 0.8], [-1.1, 0.8]], v: [[0, 1.2], [1.1, -0.8], [-1.1, -0.8]],
    "<": [[-1.2, 0], [0.8, -1.1], [0.8, 1.1]], ">": [[1.2, 0], [-0.8, -1.1], [-0.8, 1.1]],
    h: [0, 1, 2, 3, 4, 5].map(i => [Math.sin(i * Math.PI / 3), -Math.cos(i * Math.PI / 3)]),
    P: [[-0.4, -1], [0.4, -1], [0.4, -0.4], [1, -0.4], [1, 0.4], [0.4, 0.4], [0.4, 1], [-0.4, 1], [-0.4, 0.4], [-1, 0.4], [-1, -0.4], [-0.4, -0.4]],
    X: [[-0.7, -1], [0, -0.3], [0.7, -1], [1, -0.7], [0.3, 0], [1, 0.7], [0.7, 1], [0, 0.3], [-0.7, 1], [-1, 0.7], [-0.3, 0], [-1, -0.7]],
  };
  function markersPlugin(drawn) {
    return { hooks: { draw: u => {
      const c = u.ctx, r = ratio(u), size = 3 * r;  // half of 4.5 pt, in device pixels
      const b = u.bbox;
      c.save();
      c.beginPath(); c.rect(b.left, b.top, b.width, b.height); c.clip();
      drawn.forEach((s, n) => {
        if (!s.marker || !u.series[n + 1].show) return;
        const [shape, start, every] = s.marker, ys = u.data[n + 1], pts = SHAPES[shape] || [];
        const rad = s.points ? 1.7 * size : size;  // a single design (a front's mark) stands out, filled white
        c.strokeStyle = s.stroke; c.lineWidth = s.points ? 1.5 * r : r; c.setLineDash([]); c.fillStyle = "#fff";
        for (let i = start; i < ys.length; i += every) {
          if (ys[i] == null) continue;
          const x = u.valToPos(u.data[0][i], "x", true), y = u.valToPos(ys[i], "y", true);
          c.beginPath();
          if (!pts.length) c.arc(x, y, rad, 0, 2 * Math.PI);
          else pts.forEach(([px, py], j) => (j ? c.lineTo : c.moveTo).call(c, x + px * rad, y + py * rad));
          c.closePath(); if (s.points) c.fill(); c.stroke();
        }
      });
      c.restore();
    } } };
  }
  // a stage's swatch: a short stretch of its line (colour, dashes, width) with its marker in the
  // middle, as its curves are drawn; the same for the page's key (.swatch spans, filled below) and
  // every legend, its data-* attributes saying what it shows (the browser tests compare them)
  const SVG = "http://www.w3.org/2000/svg";
  function swatch(stroke, dash, width, marker) {
    const svg = document.createElementNS(SVG, "svg");
    svg.setAttribute("width", "30"); svg.setAttribute("height", "12"); svg.setAttribute("class", "swatch-svg");
    svg.setAttribute("aria-hidden", "true");
    const line = document.createElementNS(SVG, "line");
    for (const [k, v] of [["x1", 1], ["y1", 6], ["x2", 29], ["y2", 6], ["stroke", stroke], ["stroke-width", width]]) line.setAttribute(k, v);
    if (dash.length) line.setAttribute("stroke-dasharray", dash.join(" "));
    svg.appendChild(line);
    if (marker) {
      const pts = SHAPES[marker] || [], m = pts.length ? document.createElementNS(SVG, "polygon") : document.createElementNS(SVG, "circle");
      if (pts.length) m.setAttribute("points", pts.map(([x, y]) => (15 + 3 * x) + "," + (6 + 3 * y)).join(" "));
      else { m.setAttribute("cx", 15); m.setAttribute("cy", 6); m.setAttribute("r", 3); }
      m.setAttribute("fill", "#fff"); m.setAttribute("stroke", stroke); m.setAttribute("stroke-width", 1);
      svg.appendChild(m);
    }
    return svg;
  }
  function swatchData(el, stroke, dash, width, marker) {
    el.dataset.stroke = stroke; el.dataset.dash = dash.join(","); el.dataset.width = String(width); el.dataset.marker = marker || "";
  }
  document.querySelectorAll(".style-legend .swatch").forEach(el => {
    const dash = el.dataset.dash ? el.dataset.dash.split(",").map(Number) : [];
    el.appendChild(swatch(el.dataset.stroke, dash, +el.dataset.width, el.dataset.marker));
  });
  // each legend row's marker replaced by the series' swatch (uPlot's shows a solid colour), its
  // short name's long label as the row's tooltip, a simulated run's row marked .sim
  function decorate(u, drawn) {
    const rows = u.root.querySelectorAll(".u-legend .u-series");
    const first = rows.length - drawn.length;
    if (first < 0) return;
    drawn.forEach((s, n) => {
      const row = rows[first + n], th = row.querySelector("th"), m = th && th.querySelector(".u-marker");
      if (!m) return;
      const marker = s.marker ? s.marker[0] : (s.points ? "o" : "");
      m.style.border = "none"; m.style.background = "none"; m.style.width = "auto"; m.style.height = "auto";
      m.textContent = "";
      m.appendChild(swatch(s.stroke, s.dash || [], s.width, marker));
      swatchData(m, s.stroke, s.dash || [], s.width, marker);
      m.classList.add("swatch");
      if (s.long) th.title = s.long;
      if (s.sim) row.classList.add("sim");
    });
  }
  // the legend's rows back in the stages' order (uPlot lists its series in drawing order);
  // moving a row keeps its click handler and the cells that show the hovered values
  function legendInStageOrder(u, order) {
    const rows = u.root.querySelectorAll(".u-legend .u-series");  // rows[0]: the time (none in print's legend)
    const first = rows.length - order.length;
    if (first !== 0 && first !== 1) return;
    const parent = rows[0].parentNode;
    for (let i = 0; i < order.length; i++) parent.appendChild(rows[first + order.indexOf(i)]);
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
        if (!el.hidden) u.setSize({ width: Math.max(240, el.clientWidth), height: u.height });
      });
      host.dataset.shown = sel.value;
      follow(f);
    }
    sel.addEventListener("change", show);
    show();
  }
  // the figure's one toggle for its simulated runs (off at load): shows or hides them in every panel
  function simToggle(host, f, drawn) {
    const box = document.createElement("label");
    box.className = "live-sim";
    const input = document.createElement("input");
    input.type = "checkbox";
    input.checked = false;
    box.appendChild(input);
    box.appendChild(document.createTextNode(" show the pymunk simulation (dotted)"));
    input.addEventListener("change", () => {
      f.simShown = input.checked;
      host.classList.toggle("sim-shown", input.checked);
      f.plots.forEach(u => drawn.forEach((s, n) => { if (s.sim) u.setSeries(n + 1, { show: input.checked }); }));
    });
    host.insertBefore(box, host.firstChild);
  }
  // the figure as drawn, as a PNG: every panel shown (its title, plot and a legend of the curves
  // shown, each by its swatch), two a row in a figure of small multiples, on white
  function figurePng(f) {
    const shown = f.plots.filter(u => !u.root.parentNode.hidden);
    if (!shown.length) return null;
    const r = ratio(shown[0]), line = 16 * r, head = 26 * r, gap = 12 * r;
    const cols = f.host.classList.contains("live-grid") && shown.length > 1 ? 2 : 1;
    const cells = shown.map(u => {
      const entries = u.series.map((s, n) => [s, n]).filter(([s, n]) => n > 0 && s.show);
      return { u: u, entries: entries, w: u.ctx.canvas.width, h: head + u.ctx.canvas.height + entries.length * line + gap };
    });
    const w = Math.max(...cells.map(c => c.w)), heights = [];
    cells.forEach((c, i) => { const row = Math.floor(i / cols); heights[row] = Math.max(heights[row] || 0, c.h); });
    const out = document.createElement("canvas");
    out.width = w * cols; out.height = heights.reduce((a, b) => a + b, 0);
    const g = out.getContext("2d");
    g.fillStyle = "#fff"; g.fillRect(0, 0, out.width, out.height);
    cells.forEach((c, i) => {
      const x = (i % cols) * w, y = heights.slice(0, Math.floor(i / cols)).reduce((a, b) => a + b, 0);
      g.fillStyle = "#1d232b"; g.font = "bold " + (13 * r) + "px sans-serif"; g.textAlign = "center";
      g.fillText(c.u.root.querySelector(".u-title") ? c.u.root.querySelector(".u-title").textContent : "", x + c.w / 2, y + 18 * r);
      g.drawImage(c.u.ctx.canvas, x, y + head);
      g.textAlign = "left"; g.font = (11 * r) + "px sans-serif";
      c.entries.forEach(([s, n], j) => {
        const d = f.series[f.order[n - 1]], ly = y + head + c.u.ctx.canvas.height + (j + 0.6) * line, lx = x + 60 * r;
        g.save();
        g.strokeStyle = d.stroke; g.lineWidth = d.width * r; g.setLineDash((d.dash || []).map(v => v * r));
        g.beginPath(); g.moveTo(lx, ly); g.lineTo(lx + 28 * r, ly); g.stroke();
        const marker = d.marker ? d.marker[0] : (d.points ? "o" : "");
        if (marker) {
          const pts = SHAPES[marker] || [], size = 3 * r, mx = lx + 14 * r;
          g.setLineDash([]); g.lineWidth = r; g.fillStyle = "#fff"; g.beginPath();
          if (!pts.length) g.arc(mx, ly, size, 0, 2 * Math.PI);
          else pts.forEach(([px, py], k) => (k ? g.lineTo : g.moveTo).call(g, mx + px * size, ly + py * size));
          g.closePath(); g.fill(); g.stroke();
        }
        g.restore();
        g.fillStyle = "#1d232b"; g.fillText(d.label, lx + 34 * r, ly + 4 * r);
      });
    });
    return out.toDataURL("image/png");
  }
  // the PNG button beside the figure's CSV link (report: draw/live.py's downloads line)
  function pngButton(f) {
    const bar = document.querySelector('p.downloads[data-for="' + f.host.id + '"]');
    if (!bar || bar.querySelector("button.png")) return;
    const b = document.createElement("button");
    b.type = "button"; b.className = "png"; b.textContent = "figure (PNG)";
    b.addEventListener("click", () => {
      const url = figurePng(f);
      if (!url) return;
      const a = document.createElement("a");
      a.href = url; a.download = f.host.id.replace(/^live-/, "figure-") + ".png";
      document.body.appendChild(a); a.click(); a.remove();
    });
    bar.appendChild(document.createTextNode(" · "));
    bar.appendChild(b);
  }
  const figures = [], all = [];  // {host, plots, hovering, ...}: the figures over time, every figure
  let playerTime = null;
  function follow(f) {
    if (playerTime == null || f.hovering || f.timeless || f.host.offsetParent === null) return;  // hidden: skip
    f.plots.forEach(u => u.setCursor({ left: u.valToPos(playerTime, "x"), top: 20 }));
  }
  let printing = false, PrintPlot = null;
  // a figure's plots are built when its section opens (lazy): at load those outside a closed
  // <details>, the others on the details' "toggle" (a Contents entry, a deep link, "open all", a
  // click) or before printing; until then the host holds only its JSON
  const pending = new Map();  // host -> its JSON's <script>
  const closed = host => !!(host.parentElement && host.parentElement.closest("details:not([open])"));
  function buildOpen() {
    for (const [host, src] of Array.from(pending)) if (!closed(host)) { pending.delete(host); make(src, host); }
  }
  function buildAll() {
    for (const [host, src] of Array.from(pending)) { pending.delete(host); make(src, host); }
  }
  document.querySelectorAll("script[type='application/json'][data-live]").forEach(src => {
    const host = document.getElementById(src.dataset.live);
    if (host) pending.set(host, src);
  });
  document.addEventListener("toggle", e => { if (e.target.open) buildOpen(); }, true);
  function make(src, host) {
    const d = JSON.parse(src.textContent);
    if (!d.panels.length) { host.classList.add("live-empty"); return; }
    const f = { host: host, plots: [], hovering: false, timeless: !!d.x };
    if (d.panels.length > 2 || d.grid) host.classList.add("live-grid");  // small multiples: as many columns as fit
    const width = el => Math.max(240, el.clientWidth);
    // drawn in d.draw's order (wide lines first, under the thin ones), listed in the stages' order
    const order = d.draw || d.series.map((s, i) => i);
    const drawn = order.map(i => d.series[i]);
    // simulated runs (pymunk) hidden until the figure's toggle shows them
    const sims = drawn.some(s => s.sim);
    f.simShown = false;
    f.build = (p, Plot, w, extra) => {  // panel p's plot by the uPlot `Plot`, w wide, in its element
      // over time, or (d.x) over another quantity: a front's budget, each value a design marked
      const series = [{ label: d.x || "t (s)", value: (u, v) => fmt(v) }].concat(drawn.map(s => Object.assign({
        label: s.label, stroke: s.stroke, dash: s.dash, width: s.width, value: (u, v) => fmt(v, p.floor),
        show: !s.sim || f.simShown,
      }, d.x ? { spanGaps: true, points: { show: !s.marker, size: s.points ? 10 : 5, width: 1.5, fill: "#fff" } } : {},
         s.points ? { paths: () => null } : {})));
      const opts = Object.assign({
        title: p.title, width: w, height: plotHeight(p.axis),
        // p.log: a log10 axis; p.range, p.xrange: the axes' limits (a front's plot, its outliers named in the caption)
        scales: Object.assign(p.log ? { x: { time: false }, y: { distr: 3 } } : { x: { time: false } },
          p.range ? { y: { range: p.range } } : {}, p.xrange ? { x: { time: false, range: p.xrange } } : {}),
        // a log axis: every decade's split reaches ticks(), which labels every k-th (uPlot's own
        // filter kept every k-th counted from the top, which could miss each of ours: no label)
        axes: [{ label: d.x || "time (s)" }, Object.assign({ label: p.axis, labelFont: LABEL_FONT, size: 64, values: ticks(!!p.log) },
                                                         p.log ? { filter: (u, splits) => splits } : {})],
        series: series,
        cursor: { sync: { key: src.dataset.live } },
        plugins: (d.marks.length ? [marksPlugin(d.marks)] : []).concat(drawn.some(s => s.marker) ? [markersPlugin(drawn)] : []),
      }, extra || {});
      return [opts, [d.t].concat(drawn.map(s => s.y[p.key] || d.t.map(() => null)))];
    };
    f.order = order;
    f.series = d.series;
    f.panels = d.panels;
    for (const p of d.panels) {
      const el = document.createElement("div");
      el.className = "live-plot";
      el.dataset.quantity = p.key;
      host.appendChild(el);
      const [opts, data] = f.build(p, uPlot, width(el));
      const u = new uPlot(opts, data, el);
      decorate(u, drawn);
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
    if (sims) simToggle(host, f, drawn);
    pngButton(f);
    host.classList.add("live-ready");
    host.uplots = f.plots;  // the drawn plots, for the console and the browser tests
    all.push(f);
    if (!d.x) figures.push(f);
    // follow the host's width (the window, or a collapsed section opened), and take each panel's
    // width once the page is laid out (a plot drawn while the layout was not final, narrower
    // than its panel, is widened when the page has loaded): resize after the observer's
    // callback, never inside it, only the plots whose panel's width differs from theirs
    let frame = 0;
    const refit = () => {
      if (host.clientWidth === 0 || printing) return;
      cancelAnimationFrame(frame);
      frame = requestAnimationFrame(() => {
        const stale = f.plots.filter(u => !u.root.parentNode.hidden && u.width !== width(u.root.parentNode));
        stale.forEach(u => u.setSize({ width: width(u.root.parentNode), height: u.height }));
        if (stale.length) follow(f);
      });
    };
    new ResizeObserver(refit).observe(host);
    if (document.readyState === "complete") refit(); else addEventListener("load", refit);
    follow(f);
  }
  buildOpen();
  // printing: every panel drawn again for the paper (see the top), with the screen plot's curves
  // shown or hidden and its time range (a zoom), no cursor; a legend without values
  function printUPlot() {  // uPlot drawing at PRINT_RATIO: its own copy, read while devicePixelRatio says so
    if (PrintPlot) return PrintPlot;
    const src = document.getElementById("uplot-js");
    if (!src) return uPlot;
    const own = Object.getOwnPropertyDescriptor(window, "devicePixelRatio");
    try {
      Object.defineProperty(window, "devicePixelRatio", { value: PRINT_RATIO, configurable: true, writable: true });
      PrintPlot = new Function(src.textContent + "\nreturn uPlot;")();
    } catch (e) {
      PrintPlot = uPlot;  // the screen's ratio, stretched
    }
    if (own) Object.defineProperty(window, "devicePixelRatio", own); else delete window.devicePixelRatio;
    return PrintPlot;
  }
  function toPrint() {
    if (printing) return;
    buildAll();  // the folded sections' figures too
    printing = true;
    const Make = printUPlot();
    all.forEach(f => {
      const w = f.host.classList.contains("live-grid") ? (PRINT_WIDTH - PRINT_GAP) / 2 : PRINT_WIDTH;
      f.plots.forEach((u, i) => {
        const [opts, data] = f.build(f.panels[i], Make, w, { cursor: { show: false }, legend: { live: false } });
        opts.series.forEach((s, n) => { s.show = u.series[n].show; });
        const box = document.createElement("div");
        box.className = "live-print";
        u.root.parentNode.appendChild(box);
        u.root.parentNode.classList.add("printed");
        const p = new Make(opts, data, box);
        decorate(p, f.order.map(i => f.series[i]));
        legendInStageOrder(p, f.order);
        const x = u.scales.x;
        if (x.min != null && (x.min > data[0][0] || x.max < data[0][data[0].length - 1])) p.setScale("x", { min: x.min, max: x.max });
        (f.printed = f.printed || []).push(p);
      });
    });
  }
  function fromPrint() {
    if (!printing) return;
    printing = false;
    all.forEach(f => {
      (f.printed || []).forEach(p => { const box = p.root.parentNode; p.destroy(); box.parentNode.classList.remove("printed"); box.remove(); });
      f.printed = [];
    });
  }
  addEventListener("beforeprint", toPrint);
  addEventListener("afterprint", fromPrint);
  const printMedia = matchMedia("print");
  printMedia.addEventListener("change", e => (e.matches ? toPrint : fromPrint)());
  if (printMedia.matches) toPrint();
  window.balpipeLive = { fmt: fmt };  // the values' format, shared with whatif.js
  document.addEventListener("balpipe:time", e => {
    playerTime = e.detail.time;
    figures.forEach(follow);
  });
})();
