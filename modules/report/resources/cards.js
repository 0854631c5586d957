// ColonFlat report cards, shared by the run report (report.js) and the supine-prone review
// (modules/register/resources/review.js): DOM helpers, position texts and the finding card
// (facts, colon-map crop, the three CT planes in two windows, endoluminal view). No network access.
"use strict";
// R: one run's page data ({ct, image, known, ...}, the JSON report.cpp writes).
// opts: {focus(key) (optional: the card's "show on map and CT" button), idPrefix (card ids "card-<prefix><key>")}.
window.colonflatCards = function (R, opts) {
  opts = opts || {};
  // ---- small helpers ----------------------------------------------------------------------
  function el(tag, attrs, children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "text") e.textContent = v;
      else if (k === "on") for (const [ev, fn] of Object.entries(v)) e.addEventListener(ev, fn);
      else if (v !== undefined && v !== null) e.setAttribute(k, v);
    }
    for (const c of children || []) if (c) e.appendChild(typeof c === "string" ? document.createTextNode(c) : c);
    return e;
  }
  function svg(tag, attrs) {
    const e = document.createElementNS("http://www.w3.org/2000/svg", tag);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    return e;
  }
  const fix = (v, d) => (typeof v === "number" ? v.toFixed(d === undefined ? 1 : d) : String(v));
  const lpsText = (p) => "(" + p.map((v) => fix(v, 1)).join(", ") + ")";
  const fromText = (f) => (f === "rectum" ? "the rectal end" : f || "end A");

  // What the views show: the CT, or the lumen mask of a run without a CT.
  const volumeName = () => (R.ct && R.ct.is_mask ? "Lumen mask (no CT)" : "CT");
  // CT voxel index (continuous) of an LPS point, and the text shown for it.
  function ctIndex(lps) {
    if (!R.ct) return null;
    const d = [0, 1, 2].map((k) => lps[k] - R.ct.origin_lps_mm[k]);
    return R.ct.lps_to_index.map((row) => row[0] * d[0] + row[1] * d[1] + row[2] * d[2]);
  }
  function sliceText(lps) {
    const idx = ctIndex(lps);
    if (!idx) return "no CT";
    const r = idx.map(Math.round), n = R.ct.size;
    const inside = r.every((v, k) => v >= 0 && v < n[k]);
    return "voxel (" + r.join(", ") + "), axial image " + (r[2] + 1) + "/" + n[2] + (inside ? "" : " (outside the CT)");
  }
  function positionText(f) {
    if (f.along_mm === undefined) return "not on the flat map";
    return fix(f.along_mm / 10, 1) + " cm from " + fromText(f.from) + ", segment " + (f.segment + 1);
  }
  function crosshair(view) {
    view.appendChild(el("div", { class: "xh-h" }));
    view.appendChild(el("div", { class: "xh-v" }));
  }

  // ---- the card ---------------------------------------------------------------------------------
  function tile(src, label, cls, extra) {
    const t = el("div", { class: "tile" }, [src ? el("img", { src: src, alt: label, class: cls || "" }) : null]);
    for (const e of extra || []) t.appendChild(e);
    t.appendChild(el("span", { class: "lab", text: label }));
    return t;
  }
  function ctTiles(f) {
    const box = el("div", { class: "ct-views" });
    for (const plane of ["axial", "coronal", "sagittal"]) {
      const p = f.ct[plane];
      // a run from a lumen mask has no CT: one mask view (lumen white) per plane
      const imgs = p.mask ? [el("img", { src: p.mask, alt: plane + " lumen mask", class: "lung" })]
        : [el("img", { src: p.lung, alt: plane + " lung window", class: "lung" }),
           el("img", { src: p.soft, alt: plane + " soft-tissue window", class: "soft" })];
      const t = el("div", { class: "tile ct-tile", "data-plane": plane }, imgs);
      crosshair(t);
      t.appendChild(el("span", { class: "lab", text: plane + " · FOV " + fix(f.fov_mm, 0) + " mm" }));
      box.appendChild(t);
    }
    return box;
  }
  function windowButtons(card) {
    const lung = el("button", { type: "button", class: "active", text: "lung window (L -200 / W 1500)" });
    const soft = el("button", { type: "button", text: "soft tissue (L 40 / W 400)" });
    lung.onclick = () => { card.classList.remove("window-soft"); lung.classList.add("active"); soft.classList.remove("active"); };
    soft.onclick = () => { card.classList.add("window-soft"); soft.classList.add("active"); lung.classList.remove("active"); };
    return el("div", { class: "window-buttons" }, [lung, " ", soft]);
  }
  function matchBadge(f) {
    if (f.known) return f.match ? el("span", { class: "badge hit", text: "detected as " + f.match.key + ", " + fix(f.match.distance_mm) + " mm away" })
                                : el("span", { class: "badge miss", text: "not detected" });
    if (!(R.known || []).length) return null;
    return f.match ? el("span", { class: "badge hit", text: "true positive: " + f.match.key + ", " + fix(f.match.distance_mm) + " mm away" })
                   : el("span", { class: "badge miss", text: "no known polyp within reach: false positive" });
  }
  function factsTable(f, extraRows) {
    const rows = [["position", positionText(f)], ["LPS", lpsText(f.lps_mm) + " mm"], ["CT", sliceText(f.lps_mm)]];
    if (f.surface_distance_mm !== undefined) rows.push(["to the wall mesh", fix(f.surface_distance_mm) + " mm"]);
    if (f.type) rows.push(["type", f.type]);
    if (f.endoluminal_distance_mm !== undefined) rows.push(["3D view from", fix(f.endoluminal_distance_mm) + " mm inside the lumen"]);
    const cell = (v) => el("td", typeof v === "string" ? { text: v } : {}, typeof v === "string" ? [] : [v]);
    return el("table", { class: "facts" }, rows.concat(extraRows || []).map(([k, v]) => el("tr", {}, [el("td", { text: k }), cell(v)])));
  }
  // A finding's card. extra (optional): {title: shown instead of the key, head: [elements] replacing the size/score/badge part,
  // facts: [[label, text or element]] added to the facts, cls: added class}.
  function card(f, extra) {
    extra = extra || {};
    const head = el("div", { class: "card-head" }, [el("span", { class: "key", text: extra.title || f.key })].concat(extra.head || [
      el("span", { text: fix(f.size_mm) + " mm" }),
      f.known ? null : el("span", { text: "score " + fix(f.score, 2) }),
      matchBadge(f)]).concat([
      opts.focus ? el("button", { type: "button", text: "show on map and CT", on: { click: () => opts.focus(f.key, false) } }) : null]));
    const cls = "card " + (f.known ? "known" : "candidate") + (extra.cls ? " " + extra.cls : "");
    const c = el("div", { class: cls, id: "card-" + (opts.idPrefix || "") + f.key, "data-key": f.key }, [head]);
    const body = el("div", { class: "card-body" }, [factsTable(f, extra.facts)]);
    if (f.flat_thumbnail) {
      const ring = el("div", { class: "ring" });
      const d = Math.max(10, (f.size_mm || 6) / R.image.pixel_size_mm * (180 / 200) + 8);
      ring.style.width = ring.style.height = d + "px";
      body.appendChild(tile(f.flat_thumbnail, "colon map", "", [ring]));
    }
    const maskNote = () => el("p", { class: "dim", text: "lumen mask (the run had no CT): lumen white" });
    if (f.ct) body.appendChild(el("div", {}, [ctTiles(f), R.ct && R.ct.is_mask ? maskNote() : windowButtons(c)]));
    if (f.endoluminal) {
      const t = tile(f.endoluminal, "endoluminal 3D", "endo");
      crosshair(t);
      body.appendChild(t);
    }
    c.appendChild(body);
    return c;
  }
  return { el, svg, fix, lpsText, fromText, volumeName, sliceText, positionText, crosshair, matchBadge, card };
};
