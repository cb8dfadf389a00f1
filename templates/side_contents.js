// The Contents beside the page on wide screens: a copy of the page's <nav class="toc"> fixed in
// the left margin (shown by style.css where the window leaves room for it, at least 1560 px), with
// the section in view marked as the page scrolls. Its links are the Contents' own: sections.js
// opens the folded section of each (one document-wide click handler).
(function () {
  "use strict";
  const toc = document.querySelector("nav.toc");
  if (!toc) return;
  const side = document.createElement("nav");
  side.className = "toc-side";
  side.setAttribute("aria-label", "Contents (side)");
  const title = document.createElement("p");
  title.className = "toc-side-title";
  title.textContent = "Contents";
  side.appendChild(title);
  const list = toc.querySelector("ol, ul");
  if (!list) return;
  side.appendChild(list.cloneNode(true));
  document.body.appendChild(side);
  document.body.classList.add("with-side");  // style.css moves the page right where it needs the room
  const links = Array.from(side.querySelectorAll('a[href^="#"]'));
  const byId = new Map();
  links.forEach(a => {
    let id = a.getAttribute("href").slice(1);
    try { id = decodeURIComponent(id); } catch (e) { /* the id as written */ }
    const el = document.getElementById(id);
    if (el) byId.set(el, a);
  });
  if (!("IntersectionObserver" in window) || !byId.size) return;
  const visible = new Set();
  const order = Array.from(byId.keys());
  const io = new IntersectionObserver(entries => {
    entries.forEach(e => { if (e.isIntersecting) visible.add(e.target); else visible.delete(e.target); });
    // the first heading in view, else the last one above the window
    let current = order.find(el => visible.has(el));
    if (!current) current = order.filter(el => el.getBoundingClientRect().top < 0).pop();
    links.forEach(a => a.classList.toggle("current", !!current && byId.get(current) === a));
  });
  order.forEach(el => io.observe(el));
})();
