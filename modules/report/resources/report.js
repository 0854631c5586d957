// ColonFlat review report: builds the page from window.REPORT (embedded JSON). No network access.
"use strict";
(function () {
  const R = window.REPORT || {};
  const $ = (id) => document.getElementById(id);

  // Helpers and the finding card, shared with the supine-prone review (cards.js).
  const { el, svg, fix, lpsText, fromText, volumeName, sliceText, positionText, crosshair, card } =
    window.colonflatCards(R, { focus: (key, scroll) => focusFinding(key, scroll) });
  const allFindings = () => (R.candidates || []).concat(R.known || []);
  const findingByKey = (key) => allFindings().find((f) => f.key === key);

  // ---- CT views -------------------------------------------------------------------------
  // One plane of the pre-rendered stacks around `lps` (field of view `fov` mm), cross-hair at it.
  function stackView(stack, lps, fov, size) {
    let best = 0;
    stack.positions.forEach((p, i) => {
      if (Math.abs(p - lps[stack.fixed_axis]) < Math.abs(stack.positions[best] - lps[stack.fixed_axis])) best = i;
    });
    const col = (stack.u_sign * lps[stack.u_axis] - stack.u0) / stack.pixel_mm + 0.5;
    const row = (stack.v_sign * lps[stack.v_axis] - stack.v0) / stack.pixel_mm + 0.5;
    const zoom = size / (fov / stack.pixel_mm);
    const view = el("div", { class: "ct-view", "data-plane": stack.plane });
    view.style.backgroundImage = "url('" + stack.files[best] + "')";
    view.style.backgroundSize = stack.w * zoom + "px " + stack.h * zoom + "px";
    view.style.backgroundPosition = size / 2 - col * zoom + "px " + (size / 2 - row * zoom) + "px";
    const axisName = ["L", "P", "S"][stack.fixed_axis];
    const off = stack.positions[best] - lps[stack.fixed_axis];
    view.appendChild(el("span", { class: "lab", text: stack.plane }));
    view.appendChild(el("span", { class: "sub", text: axisName + " " + fix(stack.positions[best], 1) + " mm (" +
      (Math.abs(off) < 0.05 ? "at the point" : fix(Math.abs(off), 1) + " mm off") + "), FOV " + fov + " mm" }));
    crosshair(view);
    return view;
  }
  function showCtAt(lps, title) {
    const box = $("ct-click");
    box.textContent = "";
    $("ct-title").textContent = title;
    if (!R.stacks) {
      box.appendChild(el("p", { class: "dim", text: "No CT views (the CT volume was not found)." }));
      return;
    }
    for (const plane of ["axial", "coronal", "sagittal"]) if (R.stacks[plane]) box.appendChild(stackView(R.stacks[plane], lps, 80, 240));
  }

  // ---- colon map viewer ----------------------------------------------------------------------
  const view = { scale: 1, tx: 0, ty: 0 };
  function applyView() {
    $("stage").style.transform = "translate(" + view.tx + "px," + view.ty + "px) scale(" + view.scale + ")";
  }
  function fitView() {
    if (!R.image) return;
    const v = $("viewer");
    // the viewer as tall as the image at full width (within 260 px .. 62 % of the window)
    const tall = R.image.height * (v.clientWidth / R.image.width);
    v.style.height = Math.round(Math.max(260, Math.min(tall, 0.62 * window.innerHeight))) + "px";
    view.scale = Math.min(v.clientWidth / R.image.width, v.clientHeight / R.image.height);
    view.tx = (v.clientWidth - R.image.width * view.scale) / 2;
    view.ty = (v.clientHeight - R.image.height * view.scale) / 2;
    applyView();
  }
  function zoomAt(factor, cx, cy) {
    const s = Math.min(8, Math.max(0.02, view.scale * factor));
    view.tx = cx - (cx - view.tx) * (s / view.scale);
    view.ty = cy - (cy - view.ty) * (s / view.scale);
    view.scale = s;
    applyView();
  }
  function centreOn(px, py, scale) {
    const v = $("viewer");
    view.scale = scale;
    view.tx = v.clientWidth / 2 - px * scale;
    view.ty = v.clientHeight / 2 - py * scale;
    applyView();
  }
  function imagePixel(ev) {
    const r = $("viewer").getBoundingClientRect();
    return [(ev.clientX - r.left - view.tx) / view.scale, (ev.clientY - r.top - view.ty) / view.scale];
  }
  // The lookup cell under an image pixel: {segment, along_mm, lps} or null (background).
  function lookup(px, py) {
    const L = R.lookup;
    if (!L) return null;
    const c = Math.floor(px / L.step_px), r = Math.floor(py / L.step_px);
    if (c < 0 || r < 0 || c >= L.cols || r >= L.rows) return null;
    const i = 5 * (r * L.cols + c);
    if (L.cells[i] < 0) return null;
    const seg = L.cells[i];
    const segs = (R.summary && R.summary.segments) || [];
    const from = (segs[seg] && segs[seg].x0_end) || "end A";
    return { segment: seg, along_mm: L.cells[i + 1] / 10, from: from,
             lps: [L.cells[i + 2] / 10, L.cells[i + 3] / 10, L.cells[i + 4] / 10] };
  }
  function hoverText(hit) {
    return "segment " + (hit.segment + 1) + " · " + fix(hit.along_mm / 10, 1) + " cm from " + fromText(hit.from) +
      " · LPS " + lpsText(hit.lps) + " mm · " + sliceText(hit.lps);
  }
  function setPin(px, py) {
    const old = document.querySelector("#marks .pin");
    if (old) old.remove();
    $("marks").appendChild(svg("circle", { class: "pin", cx: px, cy: py, r: 6 }));
  }
  function drawMarks() {
    const m = $("marks");
    m.setAttribute("width", R.image.width);
    m.setAttribute("height", R.image.height);
    for (const f of allFindings()) {
      if (!f.pixel) continue;
      const cls = f.known ? "known" : "cand";
      const r = Math.max(9, (f.size_mm || 6) / R.image.pixel_size_mm / 2 + 7);
      const c = svg("circle", { class: "mark " + cls, cx: f.pixel[0], cy: f.pixel[1], r: r, "data-key": f.key });
      c.addEventListener("click", (ev) => { ev.stopPropagation(); focusFinding(f.key, false); });
      c.appendChild(svg("title", {})).textContent = f.key;
      m.appendChild(c);
      const t = svg("text", { class: cls + "-label", x: f.pixel[0] + r * 0.8, y: f.pixel[1] + (f.known ? r + 14 : -r * 0.8) });
      t.textContent = f.key;
      m.appendChild(t);
    }
  }
  function setUpViewer() {
    if (!R.image) {
      $("viewer").replaceWith(el("p", { class: "dim", text: "No colon image in this run." }));
      return;
    }
    const img = $("colon-img");
    img.src = R.image.file;
    img.width = R.image.width;
    img.height = R.image.height;
    drawMarks();
    const v = $("viewer");
    let drag = null;
    v.addEventListener("wheel", (ev) => {
      ev.preventDefault();
      const r = v.getBoundingClientRect();
      zoomAt(ev.deltaY < 0 ? 1.2 : 1 / 1.2, ev.clientX - r.left, ev.clientY - r.top);
    }, { passive: false });
    v.addEventListener("mousedown", (ev) => { drag = { x: ev.clientX, y: ev.clientY, tx: view.tx, ty: view.ty, moved: false }; });
    window.addEventListener("mouseup", (ev) => {
      if (drag && !drag.moved && v.contains(ev.target)) clickMap(imagePixel(ev));
      drag = null;
    });
    v.addEventListener("mousemove", (ev) => {
      if (drag) {
        const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
        if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
        view.tx = drag.tx + dx;
        view.ty = drag.ty + dy;
        applyView();
      }
      const hit = lookup(...imagePixel(ev));
      $("readout").textContent = hit ? hoverText(hit) : R.lookup ? "outside the colon wall" : "no position lookup for this image";
    });
    $("zoom-fit").onclick = fitView;
    $("zoom-in").onclick = () => zoomAt(1.5, v.clientWidth / 2, v.clientHeight / 2);
    $("zoom-out").onclick = () => zoomAt(1 / 1.5, v.clientWidth / 2, v.clientHeight / 2);
    $("zoom-1").onclick = () => zoomAt(1 / view.scale, v.clientWidth / 2, v.clientHeight / 2);
    $("show-candidates").onchange = (ev) => $("marks").classList.toggle("hide-cand", !ev.target.checked);
    $("show-known").onchange = (ev) => $("marks").classList.toggle("hide-known", !ev.target.checked);
    fitView();
    window.addEventListener("resize", fitView);
  }
  function clickMap(p) {
    const hit = lookup(p[0], p[1]);
    if (!hit) return;
    setPin(p[0], p[1]);
    showCtAt(hit.lps, volumeName() + " at the clicked point: " + hoverText(hit));
  }

  // Shows a finding: selects its card, centres the map on it (unless keepMap), CT planes there.
  // scroll: to the card.
  function focusFinding(key, scroll, keepMap) {
    const f = findingByKey(key);
    if (!f) return;
    document.querySelectorAll(".card.selected").forEach((c) => c.classList.remove("selected"));
    const card = $("card-" + key);
    if (card) card.classList.add("selected");
    if (f.pixel && R.image) {
      if (!keepMap) centreOn(f.pixel[0], f.pixel[1], Math.max(view.scale, 1.5));
      setPin(f.pixel[0], f.pixel[1]);
    }
    showCtAt(f.lps_mm, volumeName() + " at " + key + ": " + positionText(f) + " · LPS " + lpsText(f.lps_mm) + " mm · " + sliceText(f.lps_mm));
    if (scroll && card) card.scrollIntoView({ block: "start" });
  }
  window.colonflatFocus = focusFinding;

  // ---- cards ----------------------------------------------------------------------------------
  function indexTable(list, known) {
    if (!list.length) return el("p", { class: "dim", text: known ? "No known polyps for this run." : "No polyp candidates." });
    const head = known ? ["id", "diameter", "type", "position", "detected as"] : ["id", "size", "score", "position", "truth"];
    const rows = list.map((f) => {
      const cells = known ? [f.key, fix(f.size_mm) + " mm", f.type || "", positionText(f), f.match ? f.match.key : "missed"]
                          : [f.key, fix(f.size_mm) + " mm", fix(f.score, 2), positionText(f), f.match ? f.match.key : (R.known || []).length ? "false positive" : ""];
      const tr = el("tr", { class: "clickable", title: "show " + f.key }, cells.map((v) => el("td", { text: v })));
      tr.addEventListener("click", () => focusFinding(f.key, true));
      return tr;
    });
    return el("table", {}, [el("tr", {}, head.map((h) => el("th", { text: h })))].concat(rows));
  }
  function buildCards() {
    const cands = R.candidates || [], known = R.known || [];
    $("candidate-index").appendChild(indexTable(cands, false));
    for (const f of cands) $("candidate-list").appendChild(card(f));
    if (!known.length) {
      $("known-index").appendChild(el("p", { class: "dim", text: "No known polyps (truth) for this run: pass --truth FILE to `colonflat report`." }));
      return;
    }
    $("known-index").appendChild(indexTable(known, true));
    for (const f of known) $("known-list").appendChild(card(f));
  }

  // ---- segmentation QC ----------------------------------------------------------------------------
  // Montages per plane with a numbered tag per rejected body where it shows (its box placed by the
  // report in image pixels, so the tag scales with the image; the reason's colour), the reason key
  // above them, the legend (number, reason, volume, slices where seen) and the kept bodies below.
  const pct = (v, of) => (100 * v / of).toFixed(3) + "%";
  function segTag(t, im, b, r) {
    const cq = (px) => (100 * px / im.w).toFixed(3) + "cqw";  // image pixels in the figure's width
    const tag = el("span", { class: "seg-tag", "data-body": String(t.id), text: String(t.id),
      title: t.id + ": " + fix(b.volume_ml, 0) + " mL, " + (b.reason || "") });
    Object.assign(tag.style, { left: pct(t.x, im.w), top: pct(t.y, im.h), width: pct(t.w, im.w), height: pct(t.h, im.h),
      fontSize: cq(0.8 * t.h), lineHeight: cq(t.h), background: r.colour || "rgb(255,50,30)", color: r.ink || "#fff" });
    return tag;
  }
  function segSlice(plane, n, im, byId, reasons) {
    const box = el("div", { class: "seg-img" }, [el("img", { src: im.file, alt: plane + " " + im.axis + " " + im.position_mm + " mm" })]);
    for (const t of im.tags || []) if (t.placed) box.appendChild(segTag(t, im, byId[t.id] || {}, reasons[(byId[t.id] || {}).reason_index] || {}));
    return el("figure", { class: "seg-slice", "data-plane": plane }, [box,
      el("figcaption", { text: plane + " " + n + " · " + im.axis + " " + fix(im.position_mm, 1) + " mm" })]);
  }
  const swatch = (b, r) => el("span", { class: "seg-swatch", style: "background:" + (r.colour || "") + ";color:" + (r.ink || "#fff"), text: String(b.id) });
  function seenText(b) {
    const by = {};
    for (const s of b.seen || []) (by[s.plane] = by[s.plane] || []).push(s.slice);
    const t = Object.entries(by).map(([p, v]) => p + " " + v.join(", ")).join("; ");
    return t || "on no slice shown";
  }
  function segReasonKey(bodies, reasons) {
    return el("ul", { class: "seg-key" }, reasons.map((r, i) => {
      const mine = bodies.filter((b) => b.reason_index === i);
      return el("li", { class: "seg-reason" }, [el("span", { class: "seg-swatch", style: "background:" + r.colour }), " " + r.reason + " (" +
        mine.length + ", " + fix(mine.reduce((a, b) => a + b.volume_ml, 0), 0) + " mL): " + mine.map((b) => b.id).join(", ")]);
    }));
  }
  function segLegend(bodies, reasons) {
    const rows = bodies.map((b) => el("tr", { class: "seg-rejected", "data-body": String(b.id) }, [el("td", {}, [swatch(b, reasons[b.reason_index] || {})])].concat(
      [b.reason, fix(b.volume_ml, 1) + " mL", b.what + " (" + b.kind + ")", seenText(b),
        b.outlined ? fix(b.measured_ml, 1) + " mL" + (b.truncated ? " (grown to 3x, stopped)" : "") :
        b.too_large ? "not drawn: over twice the lumen's volume (outside air)" : "not found near its position",
        lpsText(b.position_lps_mm)].map((v) => el("td", { text: v })))));
    return el("table", { class: "seg-table seg-legend" }, [el("tr", {}, ["#", "reason", "volume (segment)", "what", "seen on slices",
      "outlined here", "LPS mm"].map((h) => el("th", { text: h })))].concat(rows));
  }
  function buildSegmentation() {
    const S = R.segmentation || {}, body = $("segmentation-body");
    if (!S.planes) {
      body.appendChild(el("p", { class: "dim", text: "No segmentation view: " + (S.missing || "no data") + "." }));
      return;
    }
    const bodies = S.bodies || [], reasons = S.reasons || [], byId = {};
    bodies.forEach((b) => (byId[b.id] = b));
    const small = S.small_rejected || {};
    body.appendChild(el("p", { text: "Lumen " + fix(S.lumen_ml, 0) + " mL in " + (S.segment_volumes_ml || []).length + " segment(s); " +
      bodies.length + " rejected bodies of " + fix(S.min_body_ml, 0) + " mL or more (" + fix(bodies.reduce((a, b) => a + b.volume_ml, 0), 0) + " mL)" +
      (small.count ? "; " + small.count + " smaller rejected bodies (" + fix(small.volume_ml, 1) + " mL) not drawn" : "") + "." }));
    if (bodies.length) body.appendChild(segReasonKey(bodies, reasons));
    for (const plane of ["coronal", "axial", "sagittal"]) {
      body.appendChild(el("h3", { text: plane }));
      body.appendChild(el("div", { class: "montage", "data-plane": plane }, (S.planes[plane] || []).map((im, i) => segSlice(plane, i + 1, im, byId, reasons))));
    }
    body.appendChild(el("h3", { text: "Rejected bodies (" + fix(S.min_body_ml, 0) + " mL or more): legend of the tags" }));
    body.appendChild(segLegend(bodies, reasons));
    body.appendChild(el("h3", { text: "Kept" }));
    body.appendChild(el("table", { class: "seg-table" }, [el("tr", {}, ["what", "volume", "reason"].map((h) => el("th", { text: h })))].concat(
      (S.kept || []).map((k) => el("tr", { class: "seg-kept" }, [k.what, fix(k.volume_ml, 1) + " mL", k.reason].map((v) => el("td", { text: v })))))));
  }

  // ---- run summary ------------------------------------------------------------------------------
  // A stage's result as "key: value" lines (nested objects flattened one level, long arrays cut).
  function resultLines(result, prefix, out) {
    for (const [k, v] of Object.entries(result || {})) {
      const name = prefix ? prefix + "." + k : k;
      if (v && typeof v === "object" && !Array.isArray(v) && !prefix) resultLines(v, name, out);
      else {
        let s = JSON.stringify(v);
        if (s.length > 160) s = s.slice(0, 157) + "...";
        out.push([name, s]);
      }
    }
    return out;
  }
  function stageTable(stages) {
    const rows = stages.map((s) => el("tr", {}, [
      el("td", { text: s.stage }), el("td", { text: fix(s.time_s, 2) + " s" }), el("td", { text: fix(s.peak_memory_mib, 0) + " MiB" }),
      el("td", {}, [el("details", {}, [el("summary", { text: "all result fields" }), el("table", { class: "kv" }, resultLines(s.result, "", []).map(([k, v]) =>
        el("tr", { class: /warn|error/i.test(k) ? "warning" : "" }, [el("td", { text: k }), el("td", { text: v })])))])])]));
    return el("table", { class: "stages" }, [el("tr", {}, ["stage", "time", "peak memory", "result"].map((h) => el("th", { text: h })))].concat(rows));
  }
  const num = (v) => (typeof v === "number" ? (Number.isInteger(v) ? String(v) : v.toPrecision(4).replace(/\.?0+$/, "")) : JSON.stringify(v));
  // The results a reader looks for first, picked by field name from every stage's result.
  const KEY_FACTS = [
    [/^(lumen_volume_ml|fluid_volume_ml|segments|segment_volumes_ml)$/, "segmentation"],
    [/^(genus|faces|manifold|closed|components)$/, "surface"],
    [/^(genus_before|genus_after|totals\.loops|totals\.loop_length_mm)$/, "topology"],
    [/(coverage|quasi_conformal_(mean|p95)|area_ratio_median|flipped_triangles|segment_count)/, "flat map"],
    [/^(candidates|score_vs_known\..*)$/, "candidates"]];
  function keyFacts(stages) {
    const rows = [];
    for (const s of stages)
      for (const [k, v] of Object.entries(flatResult(s.result, ""))) {
        const hit = KEY_FACTS.find(([re]) => re.test(k));
        if (hit) rows.push(el("tr", {}, [el("td", { text: hit[1] }), el("td", { text: s.stage + ": " + k.replace(/_/g, " ") }), el("td", { text: num(v) })]));
      }
    return el("table", { class: "kv facts-table" }, rows);
  }
  function flatResult(obj, prefix) {
    const out = {};
    for (const [k, v] of Object.entries(obj || {})) {
      const name = prefix ? prefix + "." + k : k;
      if (v && typeof v === "object" && !Array.isArray(v) && name.split(".").length < 3) Object.assign(out, flatResult(v, name));
      else out[name] = v;
    }
    return out;
  }
  function stageWarnings(stages) {
    const out = [];
    for (const s of stages) for (const [k, v] of resultLines(s.result, "", [])) if (/warn|error/i.test(k)) out.push(s.stage + ": " + k + " = " + v);
    return out;
  }
  function buildSummary() {
    const S = R.summary || {}, stages = S.stages || [];
    const body = $("summary-body");
    body.appendChild(el("p", { text: "ColonFlat " + (S.version || "") + " on " + (S.input || "?") + ": total " + fix(S.total_time_s, 1) +
      " s, peak memory " + fix(S.peak_memory_mib, 0) + " MiB" + (S.not_run ? "; stages not run: " + S.not_run : "") + "." }));
    if (S.score_vs_known) body.appendChild(el("p", { text: "Detection vs known polyps: " + JSON.stringify(S.score_vs_known) }));
    body.appendChild(el("h3", { text: "Key results" }));
    body.appendChild(keyFacts(stages));
    if ((S.segments || []).length) {
      body.appendChild(el("h3", { text: "Segments of the flat map" }));
      const keys = ["id", "input_kind", "length_mm", "period_mm", "area_3d_mm2", "x0_end", "x1_end", "centreline_length_mm"];
      body.appendChild(el("table", { class: "kv" }, S.segments.map((s) => el("tr", {}, [el("td", { text: "segment " + ((s.id || 0) + 1) }),
        el("td", { text: Object.entries(s).filter(([k, v]) => typeof v !== "object" || keys.includes(k)).map(([k, v]) => k + ": " + num(v)).join(", ") })]))));
    }
    if ((S.snapshots || []).length) {
      body.appendChild(el("h3", { text: "3D snapshots: surface before and after topological denoising (cut loops highlighted)" }));
      body.appendChild(el("div", { class: "snapshots" }, S.snapshots.map((f) => el("figure", {}, [el("img", { src: f, alt: f }), el("figcaption", { text: f })]))));
    }
    body.appendChild(el("h3", { text: "Stages: time, peak memory, every result field" }));
    body.appendChild(stageTable(stages));
    const warnings = (S.warnings || []).concat(stageWarnings(stages));
    for (const w of warnings) $("warnings").appendChild(el("p", { class: "warning", text: "Warning: " + w }));
  }
  function buildFiles() {
    const body = $("files-body");
    body.appendChild(el("p", { text: "Drag these files onto 3D Slicer (LPS millimetres throughout); see docs/slicer.md." }));
    body.appendChild(el("table", {}, (R.files || []).map((f) => el("tr", {}, [
      el("td", {}, [el("a", { href: f.file, text: f.file })]), el("td", { text: f.what })]))));
  }

  // ---- start --------------------------------------------------------------------------------------
  function start() {
    $("subtitle").textContent = "run " + (R.run_dir || "") + " · " + (R.candidates || []).length + " candidates" +
      ((R.known || []).length ? " · " + R.known.length + " known polyps" : "") + " · LPS mm · ColonFlat " + (R.version || "");
    $("footer").textContent = "Generated by colonflat report " + (R.version || "") + " from " + (R.candidates_file || "no candidates file") + ". Static page: no network access.";
    buildSummary();
    buildSegmentation();
    setUpViewer();
    buildCards();
    buildFiles();
    const first = (R.candidates || [])[0] || (R.known || [])[0];
    if (first) focusFinding(first.key, false, true);
    else $("ct-title").textContent = volumeName() + ": click the map";
    document.body.setAttribute("data-ready", "1");
  }
  start();
})();
