// Search, filter and sort of the site index: no library, no external file. The state is kept in
// the address's #fragment (e.g. #verdict=bad&method=five_bar_gear_balancing&q=scott&sort=-force) so
// a filtered, sorted view can be shared. Sorting compares with table_sort.js's balpipeSortValues.
(function () {
  "use strict";
  var keys = ["verdict", "paper", "template", "method", "status"];
  var q = document.getElementById("f-q");
  var count = document.getElementById("f-count");
  var none = document.getElementById("f-none");
  var rows = Array.prototype.slice.call(document.querySelectorAll("#studies tbody.entry"));
  var table = document.getElementById("studies");
  var sortButtons = Array.prototype.slice.call(document.querySelectorAll("#studies thead button.sort"));
  var sort = "";  // "" (the build's order), "force" (ascending) or "-force" (descending)
  var sel = {};
  keys.forEach(function (k) { sel[k] = document.getElementById("f-" + k); });

  function order() {
    var k = sort.replace(/^-/, ""), dir = sort.charAt(0) === "-" ? -1 : 1;
    var sorted = rows.slice();
    if (k) {
      sorted.sort(function (a, b) {
        return window.balpipeSortValues(a.getAttribute("data-sort-" + k), b.getAttribute("data-sort-" + k), dir);
      });
    }
    sorted.forEach(function (r) { table.appendChild(r); });
    window.balpipeMarkSorted(sortButtons, sortButtons.filter(function (b) { return b.getAttribute("data-sort") === k; })[0], dir);
  }

  function apply() {
    var words = q.value.toLowerCase().split(/\s+/).filter(Boolean);
    var shown = 0;
    rows.forEach(function (r) {
      var ok = keys.every(function (k) { return !sel[k].value || r.getAttribute("data-f-" + k) === sel[k].value; }) &&
        words.every(function (w) { return r.getAttribute("data-text").indexOf(w) >= 0; });
      r.hidden = !ok;
      if (ok) { shown += 1; }
    });
    count.textContent = shown + " of " + rows.length + " shown";
    none.hidden = shown > 0 || rows.length === 0;
    var state = [];
    if (q.value) { state.push("q=" + encodeURIComponent(q.value)); }
    keys.forEach(function (k) { if (sel[k].value) { state.push(k + "=" + encodeURIComponent(sel[k].value)); } });
    if (sort) { state.push("sort=" + encodeURIComponent(sort)); }
    var frag = state.length ? "#" + state.join("&") : "";
    if (frag !== location.hash) {
      try { history.replaceState(null, "", frag || location.pathname + location.search); } catch (e) { /* file:// */ }
    }
  }

  location.hash.replace(/^#/, "").split("&").forEach(function (part) {
    var i = part.indexOf("=");
    if (i < 0) { return; }
    var k = part.slice(0, i), v = decodeURIComponent(part.slice(i + 1));
    if (k === "q") { q.value = v; }
    else if (k === "sort" && sortButtons.some(function (b) { return b.getAttribute("data-sort") === v.replace(/^-/, ""); })) { sort = v; }
    else if (sel[k] && Array.prototype.some.call(sel[k].options, function (o) { return o.value === v; })) { sel[k].value = v; }
  });
  document.getElementById("filters").addEventListener("submit", function (e) { e.preventDefault(); });
  [q].concat(keys.map(function (k) { return sel[k]; })).forEach(function (el) {
    el.addEventListener("input", apply);
    el.addEventListener("change", apply);
  });
  sortButtons.forEach(function (b) {
    b.addEventListener("click", function () {
      var k = b.getAttribute("data-sort");
      sort = sort === k ? "-" + k : k;
      order();
      apply();
    });
  });
  order();
  apply();
}());
