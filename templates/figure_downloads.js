// The static figures' downloads (report: the page's inline SVG drawings and charts): under each
// figure drawn as an SVG (not an interactive plot, not a player), a button that saves that very
// SVG as a file, and one that saves it as a PNG (drawn on a canvas at twice its size). Nothing
// is written beside the page for them: the figure in the page is the file.
(function () {
  "use strict";
  const figures = Array.from(document.querySelectorAll("main figure")).filter(f =>
    !f.matches(".mechanism-player") && !f.querySelector(".live, .player-controls, [data-player]") && f.querySelector("svg"));
  function slug(f, i) {
    const cap = f.querySelector("figcaption");
    const words = (cap ? cap.textContent : "").toLowerCase().replace(/[^a-z0-9]+/g, "-").replace(/^-|-$/g, "").slice(0, 40);
    return "drawing-" + (i + 1) + (words ? "-" + words.replace(/-[^-]*$/, "") : "");
  }
  function save(url, name) {
    const a = document.createElement("a");
    a.href = url; a.download = name;
    document.body.appendChild(a); a.click(); a.remove();
  }
  function text(svg) {
    const copy = svg.cloneNode(true);
    copy.setAttribute("xmlns", "http://www.w3.org/2000/svg");
    return '<?xml version="1.0" encoding="utf-8"?>\n' + new XMLSerializer().serializeToString(copy);
  }
  figures.forEach((f, i) => {
    const svg = f.querySelector("svg"), name = slug(f, i);
    const bar = document.createElement("p");
    bar.className = "downloads static";
    bar.appendChild(document.createTextNode("Download: "));
    const asSvg = document.createElement("button"), asPng = document.createElement("button");
    asSvg.type = asPng.type = "button";
    asSvg.className = "svg"; asSvg.textContent = "figure (SVG)";
    asPng.className = "png"; asPng.textContent = "figure (PNG)";
    asSvg.addEventListener("click", () => {
      const url = URL.createObjectURL(new Blob([text(svg)], { type: "image/svg+xml" }));
      save(url, name + ".svg");
      setTimeout(() => URL.revokeObjectURL(url), 1000);
    });
    asPng.addEventListener("click", () => {
      const box = svg.getBoundingClientRect(), img = new Image();
      img.onload = () => {
        const c = document.createElement("canvas"), k = 2;
        c.width = Math.max(1, Math.round(box.width * k)); c.height = Math.max(1, Math.round(box.height * k));
        const g = c.getContext("2d");
        g.fillStyle = "#fff"; g.fillRect(0, 0, c.width, c.height);
        g.drawImage(img, 0, 0, c.width, c.height);
        save(c.toDataURL("image/png"), name + ".png");
      };
      img.src = "data:image/svg+xml;charset=utf-8," + encodeURIComponent(text(svg));
    });
    bar.appendChild(asSvg);
    bar.appendChild(document.createTextNode(" · "));
    bar.appendChild(asPng);
    const cap = f.querySelector("figcaption");
    f.insertBefore(bar, cap);
  });
})();
