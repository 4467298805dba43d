// Sorting: a click (or Enter) on a column header of a sortable table orders its rows by that
// column, numbers by the cell's data-value; again, the other way.
function sortTable(table, header, column) {
  var ascending = header.getAttribute("aria-sort") !== "ascending";
  table.querySelectorAll("th").forEach(function (th) { th.removeAttribute("aria-sort"); });
  header.setAttribute("aria-sort", ascending ? "ascending" : "descending");
  var numeric = header.dataset.type === "number";
  var key = function (row) {
    var cell = row.cells[column];
    var value = cell.dataset.value !== undefined ? cell.dataset.value : cell.textContent;
    if (!numeric) return value;
    return value === "" ? Infinity : parseFloat(value);
  };
  var body = table.tBodies[0];
  var rows = Array.prototype.slice.call(body.rows);
  rows.sort(function (a, b) {
    var x = key(a), y = key(b);
    var order = x < y ? -1 : (x > y ? 1 : 0);
    return ascending ? order : -order;
  });
  rows.forEach(function (row) { body.appendChild(row); });
}
document.querySelectorAll("table.sortable").forEach(function (table) {
  table.querySelectorAll("th").forEach(function (header, column) {
    header.tabIndex = 0;
    header.addEventListener("click", function () { sortTable(table, header, column); });
    header.addEventListener("keydown", function (event) {
      if (event.key === "Enter" || event.key === " ") {
        event.preventDefault();
        sortTable(table, header, column);
      }
    });
  });
});
// Filters: show the boards of the chosen profile and eval mode ("all": every one).
function applyFilters() {
  var form = document.querySelector("form.filters");
  if (!form) return;
  var profile = form.elements.profile.value, mode = form.elements.eval.value;
  document.querySelectorAll(".board[data-profile]").forEach(function (board) {
    var shown = (profile === "all" || board.dataset.profile === profile) &&
      (mode === "all" || !board.dataset.eval || board.dataset.eval === mode);
    board.hidden = !shown;
  });
}
// A link can choose them: index.html?profile=default&eval=model.
var chosen = new URLSearchParams(window.location.search);
document.querySelectorAll("form.filters input").forEach(function (input) {
  if (chosen.get(input.name) === input.value) input.checked = true;
  input.addEventListener("change", applyFilters);
});
applyFilters();
