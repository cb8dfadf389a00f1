// The live what-if (report/whatif.py): a slider (and a number box) for each part's mass, position
// (x, y in its body's frame) and centroidal inertia; on every change the shaking force (Fx, Fy,
// |F|), the shaking moment and the actuators' efforts are recomputed here, in the browser, from the
// affine maps of <script id="whatif-data">: a part at (m, x, y, I) adds q = (m, m x, m y,
// I + m (x² + y²)) to its body's parameters, and each load is the computed design's series plus
// the sum over the bodies of their columns times the change of their q (exact at fixed geometry
// and motion). The curves are drawn by live_plots.js (the figure #live-whatif: the reference
// stage, the computed design and the design tried); this script replaces the tried design's
// series with uPlot's setData, now or when the plots are built. The computed design is marked on
// every slider; "Reset" restores it. Everything is shown in the page's display units (report.units:
// d.params per slider value, d.factors per panel, from report/whatif.py), while the maps, the
// values and the series stay SI: a value shown is the SI value over its unit's factor, a value
// slid or typed is multiplied by it, and the reset restores the exact SI design.
// window.balpipeWhatif holds the series and the values in SI, and the units' factors (for the
// console and the browser tests).
(function () {
  "use strict";
  const src = document.getElementById("whatif-data"), box = document.getElementById("whatif-panel");
  if (!src || !box) return;
  const d = JSON.parse(src.textContent);
  const fmt = (window.balpipeLive && window.balpipeLive.fmt) || (v => String(v));
  const liveSrc = document.querySelector("script[data-live='" + d.figure + "']");
  const fig = liveSrc ? JSON.parse(liveSrc.textContent) : { panels: [], series: [] };
  const host = document.getElementById(d.figure);
  // base64 of little-endian float64 values -> Float64Array
  function f64(b64) {
    const s = atob(b64), view = new DataView(new ArrayBuffer(s.length));
    for (let i = 0; i < s.length; i++) view.setUint8(i, s.charCodeAt(i));
    const out = new Float64Array(s.length / 8);
    for (let i = 0; i < out.length; i++) out[i] = view.getFloat64(8 * i, true);
    return out;
  }
  const n = d.n, t = f64(d.t), parts = d.parts;
  const design = {}, cols = {};
  d.keys.forEach(k => {
    design[k] = f64(d.design[k]);
    cols[k] = {};
    d.bodies.forEach(b => { cols[k][b] = d.columns[k][b].map(c => (c == null ? null : f64(c))); });
  });
  const norm = (fx, fy) => fx.map((x, i) => Math.hypot(x, fy[i]));
  design.F = norm(design.Fx, design.Fy);
  const q = v => [v[0], v[0] * v[1], v[0] * v[2], v[3] + v[0] * (v[1] * v[1] + v[2] * v[2])];
  const q0 = parts.map(p => q(p.design));
  const values = parts.map(p => p.design.slice());
  function compute() {
    const dq = {};
    d.bodies.forEach(b => { dq[b] = [0, 0, 0, 0]; });
    parts.forEach((p, i) => { const a = q(values[i]); for (let j = 0; j < 4; j++) dq[p.body][j] += a[j] - q0[i][j]; });
    const out = {};
    d.keys.forEach(k => {
      const y = Float64Array.from(design[k]);
      d.bodies.forEach(b => cols[k][b].forEach((c, j) => {
        if (!c) return;
        const s = dq[b][j];
        for (let i = 0; i < n; i++) y[i] += c[i] * s;
      }));
      out[k] = y;
    });
    out.F = norm(out.Fx, out.Fy);
    return out;
  }
  // the display units: each slider value's name, unit and factor to SI; each panel's factor
  const PARAMS = d.params;
  const factor = key => (d.factors && d.factors[key]) || 1;
  const shownSeries = (y, key) => { const f = factor(key); return Array.from(y, v => v / f); };
  const api = { t: t, design: design, series: design, values: values, parts: parts, updates: 0, drawn: 0,
    params: PARAMS, factors: d.factors };
  window.balpipeWhatif = api;

  // the controls: per part a group of four rows (range, number box, the computed value marked)
  // what a number box and a label show, in the display unit: 0 for a value within 1e-9 of its
  // slider's range of 0 (a computation's round-off, 2e-17 m); the value itself is kept whole
  const clean = (p, j, v) => (Math.abs(v) <= 1e-9 * (p.hi[j] - p.lo[j]) ? 0 : v) / PARAMS[j].factor;
  // a number box's value: fixed-point decimals to 6 significant digits, as the pages write numbers
  // (balpipe.display.numbers), never exponent notation ("0.0000275272", not "2.75272e-11")
  function plain(v) {
    if (v === 0 || !isFinite(v)) return String(v);
    const r = +v.toPrecision(6), e = Math.floor(Math.log10(Math.abs(r)));
    const s = r.toFixed(Math.min(100, Math.max(0, 5 - e)));
    return s.indexOf(".") >= 0 ? s.replace(/0+$/, "").replace(/\.$/, "") : s;
  }
  const shown = (p, j, v) => plain(clean(p, j, v));
  const inputs = [];
  const added = document.createElement("p");
  added.className = "whatif-added";
  const reset = document.createElement("button");
  reset.type = "button";
  reset.className = "whatif-reset";
  reset.textContent = "Reset to the computed design";
  const bar = document.createElement("div");
  bar.className = "whatif-bar";
  bar.append(reset, added);
  box.appendChild(bar);
  const grid = document.createElement("div");
  grid.className = "whatif-parts";
  box.appendChild(grid);
  parts.forEach((p, i) => {
    const set = document.createElement("fieldset");
    set.className = "whatif-part";
    const legend = document.createElement("legend");
    legend.textContent = p.label + " ";
    const kind = document.createElement("span");
    kind.className = "muted";
    kind.textContent = "(" + p.kind + (p.kind.indexOf(p.body) < 0 && p.label.indexOf(p.body) < 0 ? ", on " + p.body : "") + ")";
    legend.appendChild(kind);
    set.appendChild(legend);
    inputs.push(PARAMS.map(({ name: name, unit: unit, factor: f }, j) => {
      const row = document.createElement("div");
      row.className = "whatif-row";
      const label = document.createElement("label");
      const id = "whatif-" + i + "-" + j;
      label.htmlFor = id;
      label.textContent = name + " (" + unit + ")";
      const track = document.createElement("span");
      track.className = "whatif-track";
      const range = document.createElement("input");
      Object.assign(range, { type: "range", id: id, min: p.lo[j] / f, max: p.hi[j] / f, step: "any" });
      range.value = String(p.design[j] / f);
      range.dataset.part = String(i);
      range.dataset.param = String(j);
      range.setAttribute("aria-label", name + " of " + p.label + " (" + unit + ")");
      const mark = document.createElement("i");
      mark.className = "whatif-mark";
      mark.title = "computed design: " + fmt(clean(p, j, p.design[j])) + " " + unit;
      const frac = p.hi[j] > p.lo[j] ? (p.design[j] - p.lo[j]) / (p.hi[j] - p.lo[j]) : 0.5;
      mark.style.setProperty("--at", String(frac));
      track.append(range, mark);
      const num = document.createElement("input");
      Object.assign(num, { type: "number", min: p.lo[j] / f, max: p.hi[j] / f, step: "any" });
      num.value = shown(p, j, p.design[j]);
      num.setAttribute("aria-label", name + " of " + p.label + " (" + unit + "), typed");
      const was = document.createElement("span");
      was.className = "whatif-was muted";
      was.textContent = "computed " + fmt(clean(p, j, p.design[j]));
      row.append(label, track, num, was);
      set.appendChild(row);
      const take = (x, from) => {  // x in the display unit
        if (!isFinite(x)) return;
        const v = Math.min(p.hi[j], Math.max(p.lo[j], x * f));
        values[i][j] = v;
        if (from !== range) range.value = String(v / f);
        if (from !== num) num.value = shown(p, j, v);
        row.classList.toggle("moved", v !== p.design[j]);
        update();
      };
      range.addEventListener("input", () => take(range.valueAsNumber, range));
      num.addEventListener("input", () => { if (num.value !== "") take(num.valueAsNumber, num); });
      return { range: range, num: num, row: row };
    }));
    grid.appendChild(set);
  });
  reset.addEventListener("click", () => {
    parts.forEach((p, i) => p.design.forEach((v, j) => {
      values[i][j] = v;
      const c = inputs[i][j];
      c.range.value = String(v / PARAMS[j].factor); c.num.value = shown(p, j, v); c.row.classList.remove("moved");
    }));
    update();
  });

  // the peaks: reference stage, computed design, design tried, each panel's round-off floor as 0
  const table = document.createElement("table");
  table.className = "whatif-peaks";
  const head = table.insertRow();
  ["Peak", (fig.series[0] || {}).label || "reference", (fig.series[1] || {}).label || d.stage, "design tried"].forEach(text => {
    const th = document.createElement("th"); th.textContent = text; head.appendChild(th);
  });
  const peak = y => { let m = 0; for (let i = 0; i < y.length; i++) if (y[i] != null) m = Math.max(m, Math.abs(y[i])); return m; };
  const cells = fig.panels.map((p, k) => {
    const row = table.insertRow();
    row.insertCell().textContent = p.title;
    const ref = fig.series[0] && fig.series[0].y[p.key];
    const c = [row.insertCell(), row.insertCell(), row.insertCell()];
    c.forEach(x => { x.className = "num"; });
    c[0].textContent = ref ? fmt(peak(ref), p.floor) : "—";
    c[1].textContent = fmt(peak(design[p.key]) / factor(p.key), p.floor);
    return [c[2], p.floor, k];
  });
  (document.getElementById("whatif-peaks") || box).appendChild(table);

  const order = fig.draw || fig.series.map((s, i) => i);
  function redraw() {
    const plots = host && host.uplots;
    if (!plots) return;
    plots.forEach((u, k) => {
      const key = fig.panels[k] && fig.panels[k].key;
      if (!key || !api.series[key]) return;
      const data = u.data.slice();
      data[1 + order.indexOf(d.computed)] = shownSeries(design[key], key);  // whole, not the figure's 6 digits
      data[1 + order.indexOf(d.tried)] = shownSeries(api.series[key], key);
      const x = u.scales.x, first = data[0][0], last = data[0][data[0].length - 1];
      const zoomed = x.min != null && (x.min > first || x.max < last);
      const range = [x.min, x.max];
      u.setData(data);
      if (zoomed) u.setScale("x", { min: range[0], max: range[1] });
    });
    api.drawn = api.updates;  // the plots show the design of this update
  }
  let frame = 0;
  function update() {
    api.series = compute();
    api.updates++;
    const mass = values.reduce((s, v) => s + v[0], 0), was = parts.reduce((s, p) => s + p.design[0], 0);
    const mf = PARAMS[0].factor, unit = " " + PARAMS[0].unit;
    added.textContent = "Mass of the parts tried: " + fmt(mass / mf) + unit + " (computed design: " + fmt(was / mf) + unit + ").";
    cells.forEach(([cell, floor, k]) => {
      const key = fig.panels[k].key;
      cell.textContent = fmt(peak(api.series[key]) / factor(key), floor);
    });
    cancelAnimationFrame(frame);
    frame = requestAnimationFrame(redraw);
  }
  // plots built later (a folded section opened, a chart drawn lazily) get the tried design too
  if (host) new MutationObserver(() => { if (host.uplots) redraw(); }).observe(host, { attributes: true, childList: true });
  update();
  box.classList.add("whatif-ready");
})();
