"use strict";
(function () {
  const table = document.getElementById("best-table");
  const body = table.tBodies[0];
  const rows = Array.from(body.rows);
  const cell = (r, i) => r.cells[i];
  const value = (r, i) => {
    const c = cell(r, i);
    return c.dataset.v !== undefined ? parseFloat(c.dataset.v) : c.textContent;
  };
  // sort by a column on a click on its head (numbers by their data-v, text otherwise)
  Array.from(table.tHead.rows[0].cells).forEach((th, i) => {
    th.addEventListener("click", () => {
      const asc = !th.classList.contains("asc");
      Array.from(table.tHead.rows[0].cells).forEach((h) => h.classList.remove("asc", "desc"));
      th.classList.add(asc ? "asc" : "desc");
      const sorted = rows.slice().sort((a, b) => {
        const x = value(a, i), y = value(b, i);
        const c = typeof x === "number" ? x - y : String(x).localeCompare(String(y));
        return asc ? c : -c;
      });
      const frag = document.createDocumentFragment();
      sorted.forEach((r) => frag.appendChild(r));
      body.appendChild(frag);
    });
  });
  // filter rows by a text
  const shown = document.getElementById("shown");
  const count = () => { shown.textContent = rows.filter((r) => !r.hidden).length + " of " + rows.length + " rows"; };
  document.getElementById("filter").addEventListener("input", (e) => {
    const q = e.target.value.toLowerCase();
    rows.forEach((r) => { r.hidden = q !== "" && !r.textContent.toLowerCase().includes(q); });
    count();
  });
  count();
  document.body.dataset.renderMs = performance.now().toFixed(0);
  // #selftest: load every linked figure and inline image, then report in <pre id="selftest">
  if (location.hash === "#selftest") {
    const urls = Array.from(document.querySelectorAll("a[data-fig], #figures img"))
      .map((e) => e.href || e.src);
    let ok = 0, broken = [];
    const done = () => {
      const pre = document.createElement("pre");
      pre.id = "selftest";
      pre.textContent = "rows=" + rows.length + " links=" + urls.length + " ok=" + ok + " broken=" + broken.length +
        " render_ms=" + document.body.dataset.renderMs + (broken.length ? " first_broken=" + broken[0] : "");
      document.body.appendChild(pre);
    };
    let pending = urls.length;
    if (pending === 0) done();
    urls.forEach((u) => {
      const img = new Image();
      img.onload = () => { ok += img.naturalWidth > 0 ? 1 : 0; if (img.naturalWidth === 0) broken.push(u); if (--pending === 0) done(); };
      img.onerror = () => { broken.push(u); if (--pending === 0) done(); };
      img.src = u;
    });
  }
})();
