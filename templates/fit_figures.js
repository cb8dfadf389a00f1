// Figures drawn wider than a narrow window (several panels side by side) would shrink their text
// below MIN_TEXT px: such a drawing keeps at least the width at which its smallest text is
// MIN_TEXT px, and scrolls sideways inside its own box (class scroll-x), never the page's.
// Measured on the laid-out drawing, once it is shown (a collapsed section opens later); printing
// shows every drawing whole (style.css).
(function () {
  "use strict";
  const MIN_TEXT = 6;  // px on screen; tests/test_site_browser.py holds every page to it
  function fit(svg) {
    const w = svg.getBoundingClientRect().width;
    if (!w || svg.dataset.minText) return;  // hidden, or done
    let small = Infinity;
    for (const t of svg.querySelectorAll("text")) {
      const m = t.getScreenCTM();
      const size = m && parseFloat(getComputedStyle(t).fontSize) * Math.hypot(m.a, m.b);
      if (size > 0) small = Math.min(small, size);
    }
    if (!isFinite(small)) return;
    // the width at which the smallest text is MIN_TEXT px does not depend on the window
    svg.dataset.minText = "1";
    svg.style.minWidth = Math.ceil(w * MIN_TEXT / small) + "px";
    svg.parentElement.classList.add("scroll-x");
  }
  function fitAll() { document.querySelectorAll("main svg").forEach(fit); }
  fitAll();
  document.querySelectorAll("details").forEach(d => d.addEventListener("toggle", fitAll));
  addEventListener("resize", fitAll);
})();
