// ColonFlat supine-prone review: builds the page from window.REPORT (embedded JSON written by
// register's review.cpp) with the report's cards (cards.js, colonflatCards). No network access.
"use strict";
(function () {
  const R = window.REPORT || {};
  const $ = (id) => document.getElementById(id);
  const scans = R.scans || {};
  const other = (name) => (name === "supine" ? "prone" : "supine");
  const C = {};
  for (const name of ["supine", "prone"]) C[name] = window.colonflatCards(scans[name] || {}, { idPrefix: name + "-" });
  const { el, svg, fix } = C.supine;
  const rowId = (scan, key) => "row-" + scan + "-" + key;

  // "66.8 cm along, 135° from anterior"
  const placeText = (p) => fix(p.s_mm / 10, 1) + " cm along, " + fix(p.angle_deg, 0) + "° from anterior";
  function link(href, text) { return el("a", { href: href, text: text }); }
  function runLink(scan, key) {
    const rep = (scans[scan] || {}).report;
    return rep ? link(rep + (key ? "#card-" + key : ""), scan + " run report" + (key ? " (card " + key + ")" : "")) : null;
  }
  // Facts every review card adds: its registered position, where it maps in the other scan, links.
  function registeredFacts(f, otherKey) {
    const rows = [];
    if (f.registered) {
      rows.push(["registered", placeText(f.registered)]);
      rows.push(["maps to (" + other(f.scan) + ")", placeText(f.registered.maps_to)]);
    }
    if (otherKey) rows.push([other(f.scan) + " card", link("#card-" + other(f.scan) + "-" + otherKey, other(f.scan) + " " + otherKey)]);
    const rl = runLink(f.scan, f.probe_of ? null : f.key);
    if (rl) rows.push(["run report", rl]);
    return rows;
  }
  function headOf(f) {
    return [el("span", { class: "scan", text: f.scan }), el("span", { text: fix(f.size_mm) + " mm" }),
            el("span", { text: "score " + fix(f.score, 2) }), C[f.scan].matchBadge(f)];
  }
  function pairRow(p) {
    const head = el("div", { class: "pair-head" }, [
      el("span", { class: "title", text: "supine " + p.supine.key + " \u2194 prone " + p.prone.key }),
      el("span", { class: "badge hit", text: "seen in both scans" }),
      el("span", { text: "pair score " + fix(p.score, 2) + " (supine " + fix(p.supine.score, 2) + ", prone " + fix(p.prone.score, 2) + ")" }),
      el("span", { text: "after registration " + fix(p.along_mm) + " mm apart along the colon, " + fix(p.around_deg, 0) + "° around; size ratio " + fix(p.size_ratio, 2) }),
      el("span", { class: "dim", text: "alignment supported here" + (p.anchor_mm === null || p.anchor_mm === undefined ? "" : "; nearest shared landmark or anchor " + fix(p.anchor_mm / 10, 1) + " cm along") })]);
    const body = el("div", { class: "pair-body" }, [
      C.supine.card(p.supine, { head: headOf(p.supine), facts: registeredFacts(p.supine, p.prone.key) }),
      C.prone.card(p.prone, { head: headOf(p.prone), facts: registeredFacts(p.prone, p.supine.key) })]);
    return el("div", { class: "pair", id: rowId("supine", p.supine.key), "data-prone": p.prone.key }, [head, body]);
  }
  function probeCard(s) {
    const pr = s.probe, where = other(s.scan);
    if (pr.not_registered) return el("p", { class: "dim", text: "This point is outside the registered part of the colon: no " + where + " view." });
    const head = [el("span", { class: "scan", text: where }),
                  s.unaligned ? el("span", { class: "badge unaligned", text: "not aligned here - position uncertain" })
                              : el("span", { class: "badge check", text: "not found in " + where + " - check here" })];
    if (pr.match) head.push(el("span", { class: "badge hit", text: "known polyp " + pr.match.key + " " + fix(pr.match.distance_mm) + " mm from here" }));
    const facts = [["shows", where + " at the registered position of " + s.scan + " " + s.finding.key]].concat(registeredFacts(pr, null));
    const n = pr.nearest_candidate;
    facts.push(["nearest " + where + " candidate", n ? n.key + ": " + fix(n.along_mm) + " mm along, " + fix(n.around_deg, 0) + "° around (not paired)" : "none"]);
    return C[where].card(pr, { head: head, facts: facts, cls: "probe", title: "at " + s.finding.key });
  }
  function singleRow(s) {
    const f = s.finding;
    const head = el("div", { class: "pair-head" }, [
      el("span", { class: "title", text: s.scan + " " + f.key + " \u2014 not found in " + other(s.scan) }),
      s.unaligned ? el("span", { class: "badge unaligned", text: "the two scans could not be aligned here (" + other(s.scan) + " colon missing, collapsed or too far away): never paired" })
                  : el("span", { class: "dim", text: "polyps stay on the wall in both positions; stool and fluid move" })]);
    const body = el("div", { class: "pair-body" }, [C[s.scan].card(f, { head: headOf(f), facts: registeredFacts(f, null) }), probeCard(s)]);
    return el("div", { class: "pair single", id: rowId(s.scan, f.key) }, [head, body]);
  }
  function select(id) {
    const row = $(id);
    if (!row) return;
    document.querySelectorAll(".pair.selected").forEach((c) => c.classList.remove("selected"));
    row.classList.add("selected");
    row.scrollIntoView({ block: "start" });
  }
  // The row of a candidate: its own single row, or the pair it belongs to.
  function rowOf(scan, key) {
    if ($(rowId(scan, key))) return rowId(scan, key);
    const p = (R.pairs || []).find((q) => q[scan].key === key);
    return p ? rowId("supine", p.supine.key) : null;
  }
  function sideBySide() {
    if (!R.image) return;
    const img = $("sbs-img");
    img.src = R.image.file;
    img.width = R.image.width;
    img.height = R.image.height;
    const m = $("sbs-marks");
    m.setAttribute("width", R.image.width);
    m.setAttribute("height", R.image.height);
    for (const k of R.image.marks || []) {
      const c = svg("circle", { cx: k.x, cy: k.y, r: k.r + 3, "data-scan": k.scan, "data-key": k.key });
      c.appendChild(svg("title", {})).textContent = k.scan + " " + k.key;
      c.addEventListener("click", () => select(rowOf(k.scan, k.key)));
      m.appendChild(c);
    }
  }
  // Where the two scans could not be aligned (the striped stretches of the image).
  function alignmentNote() {
    const a = R.alignment;
    if (!a) return null;
    const gaps = (a.unaligned_mm || []).map((g) => fix(g[0] / 10, 1) + "\u2013" + fix(g[1] / 10, 1) + " cm");
    const text = "Alignment: " + fix(100 * (a.supported_fraction || 0), 0) + " % of the supine colon supported; pieces: supine " +
      a.pieces.supine + ", prone " + a.pieces.prone + "; shared landmarks: " + ((a.shared_landmarks || []).join(", ") || "none") +
      "; " + a.candidate_anchors + " candidate pairs used as anchors. " +
      (gaps.length ? "Could not be aligned (violet stripes; no pair is made there): " + gaps.join(", ") + " on the supine axis."
                   : "Aligned along the whole supine colon.");
    return el("p", { id: "alignment-note", class: gaps.length ? "unaligned-note" : "dim", text: text });
  }
  function indexTable() {
    const rows = [];
    const tr = (cells, id) => {
      const r = el("tr", { class: "clickable" }, cells.map((v) => el("td", { text: v })));
      r.addEventListener("click", () => select(id));
      return r;
    };
    for (const p of R.pairs || [])
      rows.push(tr(["both", "supine " + p.supine.key + " \u2194 prone " + p.prone.key, fix(p.supine.size_mm) + " / " + fix(p.prone.size_mm) + " mm",
        p.supine.registered ? placeText(p.supine.registered) : "", fix(p.score, 2)], rowId("supine", p.supine.key)));
    for (const s of R.singles || [])
      rows.push(tr([s.scan + " only", s.scan + " " + s.finding.key, fix(s.finding.size_mm) + " mm",
        s.finding.registered ? placeText(s.finding.registered) : "", fix(s.finding.score, 2)], rowId(s.scan, s.finding.key)));
    if (!rows.length) return el("p", { class: "dim", text: "No polyp candidates in either scan." });
    const head = el("tr", {}, ["seen in", "candidates", "size", "position (supine axis for pairs)", "score"].map((h) => el("th", { text: h })));
    return el("table", {}, [head].concat(rows));
  }
  function start() {
    const reg = R.registration || {};
    $("subtitle").textContent = (R.pairs || []).length + " candidate pairs · " + (R.singles || []).length +
      " seen in one scan only · supine " + fix((reg.supine_length_mm || 0) / 10, 1) + " cm, prone " + fix((reg.prone_length_mm || 0) / 10, 1) +
      " cm" + (reg.prone_reversed ? " (prone map reversed)" : "") + " · positions along the colon from the " + (reg.along_from || "start") + " · LPS mm · ColonFlat " + (R.version || "");
    for (const scan of ["supine", "prone"]) {
      const l = runLink(scan, null);
      if (l) $("run-links").appendChild(l), $("run-links").appendChild(document.createTextNode(" "));
    }
    for (const w of R.warnings || []) $("warnings").appendChild(el("p", { class: "warning", text: "Warning: " + w }));
    sideBySide();
    const note = alignmentNote();
    if (note) $("review-index").appendChild(note);
    $("review-index").appendChild(indexTable());
    for (const p of R.pairs || []) $("pair-list").appendChild(pairRow(p));
    if (!(R.pairs || []).length) $("pair-list").appendChild(el("p", { class: "dim", text: "No candidate was paired between the scans." }));
    for (const s of R.singles || []) $("single-list").appendChild(singleRow(s));
    if (!(R.singles || []).length) $("single-list").appendChild(el("p", { class: "dim", text: "Every candidate was paired." }));
    $("footer").textContent = "Generated by colonflat register " + (R.version || "") + " into " + (R.out_dir || "") + ". Static page: no network access.";
    document.body.setAttribute("data-ready", "1");
  }
  start();
})();
