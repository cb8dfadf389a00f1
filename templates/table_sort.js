// Sortable tables of the site index: no library. A header button sorts its column (again: the
// other way). Cells carry their value in data-sort (a number where the column is numeric);
// empty values sort last either way. window.balpipeSortValues is shared with index_filter.js,
// which sorts the list of studies (its rows are <tbody> groups) and keeps the order in the address.
(function () {
  "use strict";
  function key(v) {
    if (v === null || v === undefined || v === "") { return null; }
    var x = Number(v);
    return isNaN(x) ? String(v) : x;
  }
  // compare two data-sort values; empty ones last whatever the direction
  window.balpipeSortValues = function (a, b, dir) {
    var x = key(a), y = key(b);
    if (x === null || y === null) { return x === y ? 0 : (x === null ? 1 : -1); }
    if (typeof x !== typeof y) { x = String(x); y = String(y); }
    return (x < y ? -1 : x > y ? 1 : 0) * dir;
  };
  window.balpipeMarkSorted = function (buttons, active, dir) {
    buttons.forEach(function (b) {
      b.parentNode.setAttribute("aria-sort", b === active ? (dir > 0 ? "ascending" : "descending") : "none");
    });
  };
  Array.prototype.forEach.call(document.querySelectorAll("table.sortable"), function (table) {
    var buttons = Array.prototype.slice.call(table.querySelectorAll("thead button.sort"));
    var body = table.tBodies[0];
    buttons.forEach(function (btn) {
      btn.addEventListener("click", function () {
        var col = Number(btn.getAttribute("data-col"));
        var dir = btn.parentNode.getAttribute("aria-sort") === "ascending" ? -1 : 1;
        var rows = Array.prototype.slice.call(body.rows);
        rows.sort(function (r, s) {
          return window.balpipeSortValues(r.cells[col].getAttribute("data-sort"), s.cells[col].getAttribute("data-sort"), dir);
        });
        rows.forEach(function (r) { body.appendChild(r); });
        window.balpipeMarkSorted(buttons, btn, dir);
      });
    });
  });
}());
