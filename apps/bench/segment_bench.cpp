// Segmentation benchmark and acceptance table (Release):
//   segment_bench                     full-size phantoms, seeds 1-5: phantom generation and segmentation
//                                     time and peak memory, Dice against the ground-truth lumen, leaks,
//                                     polyps kept as wall, air/fluid interface kept as lumen, DICOM == NRRD
//                                     (seed 1); then the Google Benchmark cases (small phantom).
//   segment_bench --table-only        the table without Google Benchmark.
//   segment_bench --size small --seeds 1,2 --no-dicom   other sizes / seeds.
//   segment_bench --collapsed --seeds 1 --no-dicom      phantoms with a collapsed stretch (2 segments).
// Peak memory: the process's peak resident set is reset (/proc/self/clear_refs) before each step,
// so "peak" is the high-water mark of that step alone (segmentation: reading ct.nrrd included).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "colonflat/core/run_stats.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/segment/segment.h"

namespace fs = std::filesystem;

namespace {

bool reset_peak_memory() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  return bool(f);
}

struct Quality {
  double dice = 0;
  std::size_t fn = 0, fp = 0, leak = 0;  // leak: segmented voxels more than ~2 mm from the true lumen
  int polyps = 0, polyps_wall = 0;
  double interface_kept = 1;  // fraction of true-lumen voxels within 1 mm of a fluid level segmented as lumen
};

Quality evaluate(const cf::MaskImage* seg, const cf::Phantom& p) {
  Quality q;
  const cf::MaskImage* gt = p.lumen.GetPointer();
  const auto size = gt->GetLargestPossibleRegion().GetSize();
  const std::size_t nx = size[0], ny = size[1], nz = size[2], n = nx * ny * nz;
  const unsigned char* a = gt->GetBufferPointer();
  const unsigned char* b = seg->GetBufferPointer();
  std::size_t inter = 0, sa = 0, sb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    inter += a[i] && b[i];
    sa += a[i] != 0;
    sb += b[i] != 0;
  }
  q.dice = 2.0 * double(inter) / double(sa + sb);
  q.fn = sa - inter;
  q.fp = sb - inter;
  const auto sp = gt->GetSpacing();
  const int r[3] = {int(std::ceil(2.0 / sp[0])), int(std::ceil(2.0 / sp[1])), int(std::ceil(2.0 / sp[2]))};
  auto idx = [&](std::size_t i, std::size_t j, std::size_t k) { return i + nx * (j + ny * k); };
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t v = idx(i, j, k);
        if (!b[v] || a[v]) continue;
        bool near = false;
        for (int dk = -r[2]; dk <= r[2] && !near; ++dk)
          for (int dj = -r[1]; dj <= r[1] && !near; ++dj)
            for (int di = -r[0]; di <= r[0] && !near; ++di) {
              const long ii = long(i) + di, jj = long(j) + dj, kk = long(k) + dk;
              if (ii < 0 || jj < 0 || kk < 0 || ii >= long(nx) || jj >= long(ny) || kk >= long(nz)) continue;
              near = a[idx(ii, jj, kk)] != 0;
            }
        q.leak += !near;
      }
  // Polyps: at least 90 % of the head's true wall voxels (and the centre voxel) stay wall.
  for (const auto& pol : p.polyps) {
    ++q.polyps;
    const double rad = 0.5 * pol.diameter_mm;
    cf::MaskImage::PointType c;
    for (int d = 0; d < 3; ++d) c[d] = pol.center_lps_mm[d];
    cf::MaskImage::IndexType ci;
    seg->TransformPhysicalPointToIndex(c, ci);
    const int rr[3] = {int(std::ceil(rad / sp[0])), int(std::ceil(rad / sp[1])), int(std::ceil(rad / sp[2]))};
    std::size_t tissue = 0, kept = 0;
    bool centre_ok = true;
    for (int dk = -rr[2]; dk <= rr[2]; ++dk)
      for (int dj = -rr[1]; dj <= rr[1]; ++dj)
        for (int di = -rr[0]; di <= rr[0]; ++di) {
          cf::MaskImage::IndexType t = ci;
          t[0] += di;
          t[1] += dj;
          t[2] += dk;
          if (!seg->GetLargestPossibleRegion().IsInside(t)) continue;
          cf::MaskImage::PointType pt;
          seg->TransformIndexToPhysicalPoint(t, pt);
          if (pt.EuclideanDistanceTo(c) > rad || gt->GetPixel(t)) continue;
          ++tissue;
          kept += seg->GetPixel(t) == 0;
          if (di == 0 && dj == 0 && dk == 0 && seg->GetPixel(t)) centre_ok = false;
        }
    q.polyps_wall += centre_ok && tissue > 0 && kept >= 0.9 * double(tissue);
  }
  // Air/fluid interfaces.
  std::size_t tot = 0, kept = 0;
  const auto org = gt->GetOrigin();
  for (const auto& pool : p.description["colon"]["fluid_pools"]) {
    const double level = pool["level_y_lps_mm"].get<double>();
    for (std::size_t j = 0; j < ny; ++j) {
      const double y = org[1] + double(j) * sp[1];
      if (std::abs(y - level) > 1.0) continue;
      for (std::size_t k = 0; k < nz; ++k)
        for (std::size_t i = 0; i < nx; ++i) {
          const std::size_t v = idx(i, j, k);
          if (!a[v]) continue;
          ++tot;
          kept += b[v] != 0;
        }
    }
  }
  q.interface_kept = tot ? double(kept) / double(tot) : 1.0;
  return q;
}

bool same_mask(const cf::MaskImage* x, const cf::MaskImage* y) {
  const std::size_t n = x->GetLargestPossibleRegion().GetNumberOfPixels();
  if (n != y->GetLargestPossibleRegion().GetNumberOfPixels()) return false;
  return std::memcmp(x->GetBufferPointer(), y->GetBufferPointer(), n) == 0;
}

void table(const std::string& size, const std::vector<int>& seeds, bool dicom, bool collapsed) {
  const fs::path tmp = fs::temp_directory_path() / ("colonflat_segment_bench_" + std::to_string(::getpid()));
  std::printf("segment_bench: %s%s phantoms; times in s, peaks in MiB (per step%s)\n", size.c_str(),
              collapsed ? " collapsed-colon" : "",
              reset_peak_memory() ? "" : "; NOT reset: process-wide");
  std::printf("%4s %8s %8s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s %6s %6s %6s\n", "seed", "gen_s", "gen_MiB",
              "write_s", "read_s", "seg_s", "gcut_s", "seg_MiB", "lumen_mL", "dice", "fn", "fp", "leak", "polyps",
              "iface", "segs");
  double worst_dice = 1, worst_seg = 0, worst_mem = 0;
  for (int seed : seeds) {
    fs::remove_all(tmp);
    reset_peak_memory();
    cf::Stopwatch t;
    cf::PhantomOptions o;
    o.size = size;
    o.seed = std::uint64_t(seed);
    o.collapsed_segment = collapsed;
    cf::Phantom p = cf::generate_phantom(o);
    const double gen_s = t.seconds(), gen_mib = cf::peak_memory_mib();
    t.restart();
    cf::write_phantom(p, tmp, "nrrd");
    const double write_s = t.seconds();
    p.ct = nullptr;
    reset_peak_memory();
    t.restart();
    cf::CtImage::Pointer ct = cf::read_ct_volume(tmp / "ct.nrrd");
    const double read_s = t.seconds();
    cf::SegmentStats st;
    t.restart();
    cf::MaskImage::Pointer mask = cf::segment_colon(ct, {}, &st);
    const double seg_s = t.seconds(), seg_mib = cf::peak_memory_mib();
    ct = nullptr;
    const Quality q = evaluate(mask, p);
    std::printf("%4d %8.2f %8.0f %8.2f %8.2f %8.2f %8.2f %8.0f %8.1f %8.4f %7zu %7zu %7zu %3d/%-2d %6.3f %6d\n", seed,
                gen_s, gen_mib, write_s, read_s, seg_s, st.graph_cut_time_s, seg_mib, st.lumen_volume_ml, q.dice, q.fn,
                q.fp, q.leak, q.polyps_wall, q.polyps, q.interface_kept, st.segments);
    std::fflush(stdout);
    worst_dice = std::min(worst_dice, q.dice);
    worst_seg = std::max(worst_seg, read_s + seg_s);
    worst_mem = std::max(worst_mem, seg_mib);
    if (dicom && seed == seeds.front()) {
      cf::Phantom pd = cf::generate_phantom(o);
      t.restart();
      cf::write_phantom(pd, tmp / "dicom_case", "dicom");
      const double wd = t.seconds();
      pd.ct = nullptr;
      t.restart();
      cf::CtImage::Pointer ctd = cf::read_ct_volume(tmp / "dicom_case" / "dicom");
      const double rd = t.seconds();
      cf::MaskImage::Pointer md = cf::segment_colon(ctd, {}, nullptr);
      std::printf("     seed %d as a DICOM series (%zu files): written in %.2f s, read in %.2f s; mask %s the NRRD mask\n",
                  seed, std::size_t(ctd->GetLargestPossibleRegion().GetSize()[2]), wd, rd,
                  same_mask(md, mask) ? "IDENTICAL to" : "DIFFERENT from");
    }
  }
  fs::remove_all(tmp);
  std::printf("worst: dice %.4f, read+segment %.2f s, segmentation peak %.0f MiB\n", worst_dice, worst_seg, worst_mem);
  std::printf("columns: gen = phantom generation; write = ct.nrrd + ground truth; read = ct.nrrd; seg = "
              "segment_colon; gcut = its graph cut; leak = segmented voxels > 2 mm from the true lumen; polyps = "
              "polyps kept as wall; iface = true lumen within 1 mm of the fluid levels that is segmented as lumen\n");
}

void BM_SegmentSmallPhantom(benchmark::State& state) {
  cf::PhantomOptions o;
  o.size = "small";
  o.seed = 1;
  static const cf::Phantom p = cf::generate_phantom(o);
  for (auto _ : state) {
    cf::MaskImage::Pointer m = cf::segment_colon(p.ct, {});
    benchmark::DoNotOptimize(m.GetPointer());
  }
}
BENCHMARK(BM_SegmentSmallPhantom)->Unit(benchmark::kMillisecond);

void BM_GenerateSmallPhantom(benchmark::State& state) {
  cf::PhantomOptions o;
  o.size = "small";
  for (auto _ : state) {
    cf::Phantom p = cf::generate_phantom(o);
    benchmark::DoNotOptimize(p.ct.GetPointer());
  }
}
BENCHMARK(BM_GenerateSmallPhantom)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  bool table_only = false, dicom = true, collapsed = false;
  std::string size = "full";
  std::vector<int> seeds = {1, 2, 3, 4, 5};
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--table-only") table_only = true;
    else if (a == "--no-dicom") dicom = false;
    else if (a == "--collapsed") collapsed = true;
    else if (a == "--size" && i + 1 < argc) size = argv[++i];
    else if (a == "--seeds" && i + 1 < argc) {
      seeds.clear();
      std::stringstream s(argv[++i]);
      for (std::string x; std::getline(s, x, ',');) seeds.push_back(std::stoi(x));
    } else rest.push_back(argv[i]);
  }
  table(size, seeds, dicom, collapsed);
  if (table_only) return 0;
  int n = int(rest.size());
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
