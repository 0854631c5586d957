#!/usr/bin/env bash
# Cohort workflow test (issue #7): three small phantoms, one deliberately broken (its NRRD is
# truncated), processed by workflow/Snakefile; the summary CSV must have 3 rows, 2 ok (genus 0
# after denoise) and 1 failed with colonflat's error message.
#   tests/cohort_test.sh COLONFLAT_BINARY SOURCE_DIR
# Exit 77 (ctest SKIP_RETURN_CODE) when snakemake is not installed.
set -euo pipefail
colonflat=${1:?usage: $0 COLONFLAT_BINARY SOURCE_DIR}
src=${2:?usage: $0 COLONFLAT_BINARY SOURCE_DIR}
if ! command -v snakemake >/dev/null; then
  echo "SKIPPED: snakemake is not installed (scripts/install-deps.sh installs it)"
  exit 77
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/colonflat-cohort.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/in"
for seed in 1 2 3; do
  "$colonflat" phantom -o "$tmp/ph$seed" --size small --seed "$seed" >/dev/null
done
cp "$tmp/ph1/ct.nrrd" "$tmp/in/case_a.nrrd"
cp "$tmp/ph2/ct.nrrd" "$tmp/in/case_b.nrrd"
# broken case: the header and half of the compressed voxel data
size=$(stat -c %s "$tmp/ph3/ct.nrrd")
head -c $((size / 2)) "$tmp/ph3/ct.nrrd" > "$tmp/in/case_broken.nrrd"

start=$(date +%s)
snakemake -s "$src/workflow/Snakefile" --directory "$tmp" -j "$(nproc)" --quiet \
  --config input_dir=in output_dir=out colonflat="$colonflat"
echo "cohort of 3 small phantoms: $(( $(date +%s) - start )) s"
cat "$tmp/out/cohort_summary.csv"

python3 - "$tmp/out/cohort_summary.csv" <<'PY'
import csv, sys
rows = {r["case"]: r for r in csv.DictReader(open(sys.argv[1]))}
def check(cond, msg):
    if not cond:
        sys.exit("FAIL: " + msg)
check(sorted(rows) == ["case_a", "case_b", "case_broken"], f"cases {sorted(rows)}")
for c in ("case_a", "case_b"):
    r = rows[c]
    check(r["status"] == "ok" and r["exit_code"] == "0" and r["error"] == "", f"{c} not ok: {r}")
    check(int(r["segments"]) >= 1, f"{c} segments {r['segments']}")
    check(int(r["genus_before"]) >= 0 and r["genus_after"] == "0", f"{c} genus {r['genus_before']} -> {r['genus_after']}")
    check(int(r["loops"]) == int(r["genus_before"]), f"{c} loops {r['loops']} vs genus {r['genus_before']}")
    check(r["polyp_candidates"] != "", f"{c} has no polyp_candidates")
    for s in ("segment", "reconstruct", "denoise", "flatten", "render"):
        check(float(r[f"time_{s}_s"]) > 0, f"{c} time_{s}_s = {r[f'time_{s}_s']!r}")
b = rows["case_broken"]
check(b["status"] == "failed", f"case_broken status {b['status']}")
check(b["exit_code"] not in ("", "0"), f"case_broken exit code {b['exit_code']!r}")
check("error" in b["error"] and "case_broken.nrrd" in b["error"], f"case_broken error {b['error']!r}")
check(all(b[k] == "" for k in ("segments", "genus_after")), "case_broken has results")
print("cohort summary OK: 2 ok, 1 failed:", b["error"])
PY
