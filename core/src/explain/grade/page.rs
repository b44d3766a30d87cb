//! The HTML page's style and script, inline (the page loads nothing: it is sent by mail and
//! opened anywhere). The script only sorts the class table when a heading is clicked: by each
//! cell's `data-v` (a number, or text), empty cells last either way.

pub const STYLE: &str = r#"
body { font: 14px/1.45 system-ui, -apple-system, "Segoe UI", sans-serif; margin: 24px auto; max-width: 1320px; color: #1d2330; padding: 0 16px; }
h1 { font-size: 22px; margin: 0 0 6px; } h2 { font-size: 18px; margin: 28px 0 8px; border-bottom: 1px solid #d8dce4; padding-bottom: 4px; }
h3 { font-size: 16px; margin: 0 0 6px; }
.setup { color: #4a5263; margin: 4px 0; }
table { border-collapse: collapse; margin: 6px 0; }
th, td { padding: 4px 8px; border-bottom: 1px solid #e4e7ee; text-align: left; vertical-align: top; }
th { background: #f3f5f9; font-weight: 600; white-space: nowrap; }
td.n, th.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
#class th { cursor: pointer; user-select: none; }
#class th:hover { background: #e6eaf2; }
#class th.asc::after { content: " \25B2"; font-size: 10px; } #class th.desc::after { content: " \25BC"; font-size: 10px; }
#class td.reason { min-width: 240px; max-width: 380px; color: #4a5263; font-size: 13px; }
#class td.name { white-space: nowrap; }
.badge { display: inline-block; padding: 1px 8px; border-radius: 10px; font-size: 12px; font-weight: 600; white-space: nowrap; }
.correct { background: #d9f2e0; color: #17602d; } .defects { background: #fbdcdc; color: #8b1a1a; }
.wrong_mesh { background: #fde8c8; color: #8a4b00; } .unreadable, .no_dump { background: #e6e6ea; color: #444; }
.timed_out { background: #eadcf5; color: #5b2a86; }
.good { color: #17602d; font-weight: 600; } .notgood { color: #8a4b00; }
td.good, td.notgood { white-space: nowrap; }
section.student { border: 1px solid #d8dce4; border-radius: 6px; padding: 12px 16px; margin: 14px 0; }
section.student:target { outline: 3px solid #7aa7ff; }
.figures { display: grid; grid-template-columns: repeat(auto-fill, minmax(270px, 1fr)); gap: 2px 16px; margin: 8px 0; }
.figures span { color: #4a5263; }
.images { display: flex; flex-wrap: wrap; gap: 16px; margin: 10px 0; }
.images figure { margin: 0; } .images img { max-width: 100%; border: 1px solid #ccd; display: block; }
figcaption { font-size: 12px; color: #4a5263; max-width: 480px; }
.hist { display: grid; grid-template-columns: max-content 240px max-content; gap: 1px 8px; font-size: 12px; align-items: center; }
.hist .bar { background: #5b8def; height: 10px; min-width: 1px; }
.findings td { font-size: 13px; } .findings .defect { color: #8b1a1a; font-weight: 600; } .findings .warning { color: #8a4b00; }
.waived { color: #777; }
.reason-line { margin: 4px 0 8px; }
pre { background: #f6f7fa; padding: 8px; overflow-x: auto; font-size: 12px; }
.key { display: inline-block; width: 12px; height: 12px; vertical-align: -1px; border: 1px solid #999; }
a { color: #1b55c4; text-decoration: none; } a:hover { text-decoration: underline; }
"#;

pub const SCRIPT: &str = r#"
(function () {
  var table = document.getElementById('class');
  if (!table) return;
  var heads = table.tHead.rows[0].cells;
  for (var i = 0; i < heads.length; i++) {
    heads[i].addEventListener('click', (function (col) { return function () { sort(col, this); }; })(i));
  }
  function key(row, col) {
    var v = row.cells[col].getAttribute('data-v');
    if (v === null) v = row.cells[col].textContent;
    if (v === '') return null;
    var n = Number(v);
    return isNaN(n) ? v.toLowerCase() : n;
  }
  function sort(col, th) {
    var asc = !th.classList.contains('asc');
    for (var j = 0; j < heads.length; j++) heads[j].classList.remove('asc', 'desc');
    th.classList.add(asc ? 'asc' : 'desc');
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = key(a, col), y = key(b, col);
      if (x === null && y === null) return 0;
      if (x === null) return 1;
      if (y === null) return -1;
      var c = (typeof x === typeof y) ? (x < y ? -1 : x > y ? 1 : 0) : (typeof x === 'number' ? -1 : 1);
      return asc ? c : -c;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  }
})();
"#;
