#!/usr/bin/env python3
"""Cohort summary: one CSV row per case from its status file and, when it ran, its run_report.json.

   summarize.py --out cohort_summary.csv STATUS.json...

Columns: case, status (ok|failed), exit_code, error, input, segments, lumen_volume_ml,
genus_surface (reconstructed surface), genus_before / genus_after (denoise), loops (cut by
denoise), polyp_candidates, time_<stage>_s for every stage, total_time_s, peak_memory_mib,
wall_time_s (including start-up), not_run (stages skipped), outdir. A missing or unreadable
status file or report becomes a failed row with the reason, never an aborted summary.
"""
import argparse
import csv
import json
import os
import sys

STAGES = ["segment", "reconstruct", "denoise", "flatten", "render"]
COLUMNS = (["case", "status", "exit_code", "error", "input", "segments", "lumen_volume_ml", "genus_surface",
            "genus_before", "genus_after", "loops", "polyp_candidates"]
           + [f"time_{s}_s" for s in STAGES]
           + ["total_time_s", "peak_memory_mib", "wall_time_s", "not_run", "outdir"])


def load(path):
    with open(path) as f:
        return json.load(f)


def row_for(status_path):
    case = os.path.basename(os.path.dirname(status_path))
    row = {"case": case, "status": "failed"}
    try:
        st = load(status_path)
    except (OSError, ValueError) as e:
        row["error"] = f"no status file: {e}"
        return row
    for k in ("case", "status", "exit_code", "error", "input", "wall_time_s", "outdir"):
        if k in st:
            row[k] = st[k]
    if st.get("status") != "ok":
        return row
    try:
        rep = load(os.path.join(st["outdir"], "run_report.json"))
    except (OSError, ValueError, KeyError) as e:
        row.update(status="failed", error=f"unreadable run_report.json: {e}")
        return row
    res = {s.get("stage"): s.get("result", {}) for s in rep.get("stages", [])}
    for s in rep.get("stages", []):
        if s.get("stage") in STAGES:
            row[f"time_{s['stage']}_s"] = round(s.get("time_s", 0.0), 3)
    seg, rec, den, ren = (res.get(k, {}) for k in ("segment", "reconstruct", "denoise", "render"))
    row["segments"] = seg.get("segments")
    if "lumen_volume_ml" in seg:
        row["lumen_volume_ml"] = round(seg["lumen_volume_ml"], 2)
    row["genus_surface"] = rec.get("genus")
    row["genus_before"] = den.get("genus_before")
    row["genus_after"] = den.get("genus_after")
    row["loops"] = den.get("totals", {}).get("loops", len(den["loops"]) if "loops" in den else None)
    row["polyp_candidates"] = ren.get("candidates")
    row["total_time_s"] = round(rep.get("total_time_s", 0.0), 3)
    row["peak_memory_mib"] = round(rep.get("peak_memory_mib", 0.0), 1)
    row["not_run"] = rep.get("not_run", "")
    return row


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True)
    p.add_argument("status", nargs="*")
    a = p.parse_args()
    rows = sorted((row_for(s) for s in a.status), key=lambda r: r["case"])
    tmp = a.out + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in COLUMNS})
    os.replace(tmp, a.out)
    ok = sum(r["status"] == "ok" for r in rows)
    print(f"cohort summary: {len(rows)} cases, {ok} ok, {len(rows) - ok} failed -> {a.out}", file=sys.stderr)
    for r in rows:
        if r["status"] != "ok":
            print(f"  {r['case']}: {r.get('error', '')}", file=sys.stderr)


if __name__ == "__main__":
    main()
