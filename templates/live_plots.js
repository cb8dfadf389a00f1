// Interactive plots (report/live_plots.py): uPlot draws the curves of every
// <script type="application/json" data-live="ID"> into the element #ID: hover for values, drag to
// zoom (double-click resets), click a legend entry to hide a curve; the cursor follows the player.
(function () {
  "use strict";
  if (typeof uPlot === "undefined") return;
  function fmt(v) {
    if (v == null) return "—";
    const a = Math.abs(v);
    return a !== 0 && (a < 1e-3 || a >= 1e6) ? v.toExponential(3) : (+v.toPrecision(4)).toString();
  }
  document.querySelectorAll("script[type='application/json'][data-live]").forEach(src => {
    const host = document.getElementById(src.dataset.live);
    if (!host) return;
    const d = JSON.parse(src.textContent);
    const plots = [];
    const width = () => Math.max(240, host.clientWidth);
    for (const p of d.panels) {
      const el = document.createElement("div");
      el.className = "live-plot";
      el.dataset.quantity = p.key;
      host.appendChild(el);
      const series = [{ label: "t (s)", value: (u, v) => fmt(v) }].concat(d.series.map(s => ({
        label: s.label, stroke: s.stroke, dash: s.dash, width: s.width, value: (u, v) => fmt(v),
      })));
      const opts = {
        title: p.title + " (" + p.unit + ")", width: width(), height: 240,
        scales: { x: { time: false } },
        axes: [{ label: "time (s)" }, { label: p.unit, size: 60 }],
        series: series,
        cursor: { sync: { key: src.dataset.live } },
      };
      plots.push(new uPlot(opts, [d.t].concat(d.series.map(s => s[p.key])), el));
    }
    host.classList.add("live-ready");
    let timer = 0;
    addEventListener("resize", () => {
      clearTimeout(timer);
      timer = setTimeout(() => plots.forEach(u => u.setSize({ width: width(), height: 240 })), 100);
    });
    // linked to the player: its time slider moves the plots' cursor
    const slider = document.getElementById("player-time");
    if (slider) {
      const follow = () => {
        const t = d.t[0] + (d.t[d.t.length - 1] - d.t[0]) * (+slider.value) / (+slider.max || 1000);
        plots.forEach(u => u.setCursor({ left: u.valToPos(t, "x"), top: 20 }));
      };
      slider.addEventListener("input", follow);
    }
  });
})();
