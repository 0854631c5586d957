// Segmentation benchmark and acceptance table (Release):
//   segment_bench                     full-size phantoms, seeds 1-5: phantom generation and segmentation
//                                     time and peak memory, Dice against the ground-truth lumen, leaks,
//                                     polyps kept as wall, air/fluid interface kept as lumen, DICOM == NRRD
//                                     (seed 1); then the Google Benchmark cases (small phantom).
//   segment_bench --table-only        the table without Google Benchmark.
//   segment_bench --size small --seeds 1,2 --no-dicom   other sizes / seeds.
//   segment_bench --collapsed --seeds 1 --no-dicom      phantoms with a collapsed stretch (2 segments).
//   segment_bench --realistic --seeds 1,2 [--size medium] [--pad-to 450] issue 13: supine and prone phantoms (full size unless --size) with 2 fully
//                                     tagged stretches, oral contrast, bladder, aorta, rectal tube (written
//                                     and read as NRRD, PatientPosition included); --pad-to N appends copies
//                                     of the inferior slice (pelvic floor, thighs' soft tissue, the rectal
//                                     tube's channel) below the volume so the scan has N slices (the 512 x 512
//                                     x 450 case of issue 13: --pad-to 450); Dice on the original slices.
//   segment_bench --painted [--mask FILE] [--downsample N] [--cases easy,stretch,pools,bowel,hard/left-down] [--seeds 1,2]
//                                     issue 25: CTs painted around a real lumen mask (colonflat phantom
//                                     --from-mask; default ../shared/real/ctc_lumen_mask_a.nii.gz, full resolution
//                                     unless --downsample N (N x N in-plane)): easy and hard cases (a 200-250 mm
//                                     stretch filled beside other segments, pools over the folds, loops pressed
//                                     against the colon, slices 0.6-1.5 mm), supine / prone / left-down, with and
//                                     without PatientPosition; Dice, colon fluid kept, mL outside the colon.
//                                     --keep DIR: each case's CT, truth and segmentation stay in DIR/SEED-CASE-POSITION/.
//   segment_bench --real CT [--pad-to N]  a CT file without ground truth (e.g. ../shared/real/ctc_prone_a.nrrd):
//                                     read and segmentation time, CPU, peak memory, lumen / fluid / fully
//                                     tagged mL kept, segments (issue 25).
// Peak memory: the process's peak resident set is reset (/proc/self/clear_refs) before each step,
// so "peak" is the high-water mark of that step alone (segmentation: reading ct.nrrd included).
#include <benchmark/benchmark.h>
#include <itkConnectedComponentImageFilter.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "colonflat/core/run_stats.h"
#include "colonflat/phantom/mask_phantom.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/segment/segment.h"
#include "segment_bench_links.h"
#include "segment_bench_painted.h"

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

// A polyp stays wall: at least 90 % of its head's true wall voxels (and the centre voxel) are not lumen.
bool polyp_stays_wall(const cf::MaskImage* seg, const cf::MaskImage* gt, const cf::PhantomPolyp& pol) {
  const auto sp = gt->GetSpacing();
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
  return centre_ok && tissue > 0 && kept >= 0.9 * double(tissue);
}

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
  for (const auto& pol : p.polyps) ++q.polyps, q.polyps_wall += polyp_stays_wall(seg, gt, pol);
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

// 1-minute load average of the machine (other processes share the 2 cores), -1 if unknown.
double load_average() {
  std::ifstream f("/proc/loadavg");
  double load = -1;
  f >> load;
  return load;
}

// The CT with copies of its inferior slice appended below, up to `slices` slices (timing only).
cf::CtImage::Pointer pad_inferior(const cf::CtImage* ct, int slices) {
  const auto sz = ct->GetLargestPossibleRegion().GetSize();
  const std::size_t extra = std::size_t(slices) > sz[2] ? std::size_t(slices) - sz[2] : 0, slice = sz[0] * sz[1];
  auto out = cf::CtImage::New();
  out->SetRegions(cf::CtImage::SizeType{{sz[0], sz[1], sz[2] + extra}});
  out->SetSpacing(ct->GetSpacing());
  auto org = ct->GetOrigin();
  org[2] -= double(extra) * ct->GetSpacing()[2];
  out->SetOrigin(org);
  out->SetDirection(ct->GetDirection());
  out->Allocate();
  cf::set_patient_position(out.GetPointer(), cf::patient_position(ct));
  for (std::size_t k = 0; k < extra; ++k) std::memcpy(out->GetBufferPointer() + k * slice, ct->GetBufferPointer(), slice * sizeof(float));
  std::memcpy(out->GetBufferPointer() + extra * slice, ct->GetBufferPointer(), sz[2] * slice * sizeof(float));
  return out;
}

// The mask's last slices, the size of `like` (undoes pad_inferior).
cf::MaskImage::Pointer crop_to(const cf::MaskImage* m, const cf::MaskImage* like) {
  const std::size_t n = like->GetLargestPossibleRegion().GetNumberOfPixels();
  const std::size_t off = m->GetLargestPossibleRegion().GetNumberOfPixels() - n;
  auto out = cf::MaskImage::New();
  out->CopyInformation(like);
  out->SetRegions(like->GetLargestPossibleRegion());
  out->Allocate();
  std::memcpy(out->GetBufferPointer(), m->GetBufferPointer() + off, n);
  return out;
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

// Truth-based scores of a realistic phantom: fully tagged stretches kept (>= 95 % of their voxels)
// and voxels kept per truth label (3/4 small bowel, 5 bladder, 6 tube, 8 aorta).
struct RealisticScore {
  int stretches = 0, stretches_kept = 0;
  std::size_t kept_by_label[9] = {};
};
RealisticScore score_realistic(const cf::MaskImage* seg, const cf::Phantom& p) {
  RealisticScore r;
  const std::size_t n = p.lumen->GetLargestPossibleRegion().GetNumberOfPixels();
  const unsigned char* lab = p.labels->GetBufferPointer();
  const unsigned char* m = seg->GetBufferPointer();
  for (std::size_t q = 0; q < n; ++q)
    if (m[q]) ++r.kept_by_label[lab[q]];
  // Stretches: components of the true lumen without colon gas.
  auto cc = itk::ConnectedComponentImageFilter<cf::MaskImage, itk::Image<std::uint32_t, 3>>::New();
  cc->SetInput(p.lumen);
  cc->Update();
  const std::uint32_t* cl = cc->GetOutput()->GetBufferPointer();
  std::vector<unsigned char> gas(cc->GetObjectCount() + 1, 0);
  std::vector<std::size_t> size(gas.size(), 0), kept(gas.size(), 0);
  for (std::size_t q = 0; q < n; ++q) {
    if (lab[q] == 1) gas[cl[q]] = 1;
    ++size[cl[q]];
    kept[cl[q]] += m[q] != 0;
  }
  for (std::size_t l = 1; l < gas.size(); ++l)
    if (!gas[l]) ++r.stretches, r.stretches_kept += double(kept[l]) >= 0.95 * double(size[l]);
  return r;
}

void realistic_table(const std::string& size, const std::vector<int>& seeds, int pad_to) {
  const fs::path tmp = fs::temp_directory_path() / ("colonflat_segment_bench_r" + std::to_string(::getpid()));
  std::printf("segment_bench --realistic: %s phantoms, 2 fully tagged stretches, oral contrast, bladder, aorta, "
              "rectal tube%s\n", size.c_str(), pad_to > 0 ? (", padded to " + std::to_string(pad_to) + " slices").c_str() : "");
  std::printf("%4s %7s %7s %7s %7s %7s %7s %5s %8s %7s %9s %8s %7s %7s %6s %s\n", "seed", "pos", "slices", "gen_s", "read_s",
              "seg_s", "seg_cpu", "load", "seg_MiB", "dice", "stretches", "sb_vox", "bl_vox", "ao_vox", "tube", "gravity");
  for (int seed : seeds)
    for (const char* position : {"supine", "prone"}) {
      fs::remove_all(tmp);
      cf::Stopwatch t;
      cf::PhantomOptions o;
      o.size = size;
      o.seed = std::uint64_t(seed);
      o.position = position;
      o.fully_tagged_segments = 2;
      o.oral_contrast = o.excreted_contrast = o.enhanced_vessels = o.rectal_tube = true;
      cf::Phantom p = cf::generate_phantom(o);
      const double gen_s = t.seconds();
      cf::write_phantom(p, tmp, "nrrd");
      p.ct = nullptr;
      reset_peak_memory();
      t.restart();
      cf::CtImage::Pointer ct = cf::read_ct_volume(tmp / "ct.nrrd");
      if (pad_to > 0) ct = pad_inferior(ct, pad_to);
      const double read_s = t.seconds();
      cf::SegmentStats st;
      const double load = load_average();
      t.restart();
      cf::MaskImage::Pointer mask = cf::segment_colon(ct, {}, &st);
      const double seg_s = t.seconds(), seg_mib = cf::peak_memory_mib();
      const std::size_t slices = ct->GetLargestPossibleRegion().GetSize()[2];
      ct = nullptr;
      std::size_t pad_vox = 0;  // lumen segmented in the appended slices (none expected: body tissue and the tube)
      if (pad_to > 0) {
        const std::size_t extra = mask->GetLargestPossibleRegion().GetNumberOfPixels() - p.lumen->GetLargestPossibleRegion().GetNumberOfPixels();
        pad_vox = std::size_t(std::count_if(mask->GetBufferPointer(), mask->GetBufferPointer() + extra, [](unsigned char v) { return v != 0; }));
        mask = crop_to(mask, p.lumen);
      }
      const RealisticScore r = score_realistic(mask, p);
      const double dice = evaluate(mask, p).dice;
      std::printf("%4d %7s %7zu %7.2f %7.2f %7.2f %7.2f %5.1f %8.0f %7.4f %6d/%-2d %8zu %7zu %7zu %6zu %s (%s)\n", seed, position,
                  slices, gen_s, read_s, seg_s, st.cpu_time_s, load, seg_mib, dice, r.stretches_kept, r.stretches,
                  r.kept_by_label[3] + r.kept_by_label[4], r.kept_by_label[5], r.kept_by_label[8], r.kept_by_label[6],
                  st.gravity.c_str(), st.gravity_source.c_str());
      if (pad_to > 0) std::printf("     %zu lumen voxels segmented in the %zu appended slices\n", pad_vox, slices - p.lumen->GetLargestPossibleRegion().GetSize()[2]);
      std::fflush(stdout);
    }
  fs::remove_all(tmp);
  std::printf("columns: seg_s / seg_cpu = segment_colon wall-clock / user + system CPU time (getrusage, all threads); load = "
              "1-minute load average before the segmentation; seg_MiB = peak resident memory of reading (and padding) + segmentation\n");
  std::printf("columns: stretches = fully tagged stretches with >= 95 %% of their voxels segmented / in the phantom; sb_vox, bl_vox, "
              "ao_vox, tube = segmented voxels that are small bowel (contrast or gas), bladder, aorta, rectal tube\n");
}

void painted_table(const std::string& mask_file, int downsample, const std::string& only, const std::vector<int>& seeds,
                   const std::string& keep) {
  const fs::path tmp = fs::temp_directory_path() / ("colonflat_segment_bench_p" + std::to_string(::getpid()));
  cf::MaskImage::Pointer mask = cf::read_binary_mask(mask_file);
  if (downsample > 1) mask = cf::downsample_mask(mask, {downsample, downsample, 1});
  const auto sz = mask->GetLargestPossibleRegion().GetSize();
  std::printf("segment_bench --painted: %s, %zu x %zu x %zu at %.2f x %.2f x %.2f mm; pools, 4 small-bowel loops, bladder\n",
              mask_file.c_str(), sz[0], sz[1], sz[2], mask->GetSpacing()[0], mask->GetSpacing()[1], mask->GetSpacing()[2]);
  std::printf("%4s %-8s %-10s %4s %5s %7s %7s %7s %5s %7s %7s %8s %7s %7s %7s %6s %s\n", "seed", "case", "position", "hdr", "dz", "paint_s",
              "seg_s", "seg_cpu", "load", "seg_MiB", "dice", "fluid_mL", "kept_%", "long_%", "out_mL", "sb_mL", "gravity");
  for (int seed : seeds) {
    for (const PaintedCase& c : kPaintedCases) {
      if (!case_selected(only, c)) continue;
      fs::remove_all(tmp);
      cf::Stopwatch t;
      cf::MaskPhantomOptions o;
      o.seed = std::uint64_t(seed);
      o.position = c.position;
      o.position_header = c.header;
      o.long_stretch_mm = c.long_mm;
      o.deep_pools = c.deep;
      o.pressed_bowel = c.pressed;
      cf::MaskImage::Pointer m = c.slice_mm > 0 ? cf::resample_mask_slices(mask, c.slice_mm) : mask;
      cf::MaskPhantom p = cf::paint_phantom_from_mask(m, o);
      const double paint_s = t.seconds();
      const fs::path dir = keep.empty() ? tmp : fs::path(keep) / (std::to_string(seed) + "-" + c.name + "-" + c.position);
      cf::write_phantom(p.phantom, dir, "nrrd");
      p.phantom.ct = nullptr;
      reset_peak_memory();
      cf::CtImage::Pointer ct = cf::read_ct_volume(dir / "ct.nrrd");
      cf::SegmentStats st;
      const double load = load_average();
      t.restart();
      cf::MaskImage::Pointer seg = cf::segment_colon(ct, {}, &st);
      const double seg_s = t.seconds(), seg_mib = cf::peak_memory_mib();
      ct = nullptr;
      if (!keep.empty()) cf::write_mask(seg, dir / "segmentation.nrrd");
      const cf::MaskSegmentationScore s = cf::score_segmentation(seg, p.phantom);
      std::printf("%4d %-8s %-10s %4s %5.2f %7.2f %7.2f %7.2f %5.1f %7.0f %7.4f %8.1f %7.1f %7.1f %7.1f %6.1f %s (%s)\n", seed, c.name, c.position,
                  c.header ? "yes" : "no", m->GetSpacing()[2], paint_s, seg_s, st.cpu_time_s, load, seg_mib, s.dice, s.fluid_ml,
                  100 * s.fluid_kept, long_stretch_kept(p, seg), s.outside_ml, s.small_bowel_ml, st.gravity.c_str(),
                  st.gravity_source.c_str());
      print_lost_bodies(p, seg);
      dump_links(st, p, seed, std::string(c.name) + " " + c.position);
      std::fflush(stdout);
    }
  }
  fs::remove_all(tmp);
  std::printf("columns: dz = slice spacing (mm); fluid_mL = the painted colon fluid; kept_%% = its share segmented; long_%% = share "
              "of the long stretch segmented (-1: none); out_mL = segmented volume more than 2 mm from the true lumen; sb_mL = "
              "segmented small bowel\n");
}

// One CT without ground truth: time, memory and what was kept.
void real_table(const std::string& path, int pad_to) {
  std::printf("segment_bench --real %s%s\n", path.c_str(), pad_to > 0 ? (" padded to " + std::to_string(pad_to) + " slices").c_str() : "");
  std::printf("%7s %7s %7s %7s %5s %8s %9s %9s %7s %9s %s\n", "slices", "read_s", "seg_s", "seg_cpu", "load", "peak_MiB", "lumen_mL",
              "fluid_mL", "segs", "tagged_mL", "gravity");
  reset_peak_memory();
  cf::Stopwatch t;
  cf::CtImage::Pointer ct = cf::read_ct_volume(path);
  if (pad_to > 0) ct = pad_inferior(ct, pad_to);
  const double read_s = t.seconds(), load = load_average();
  cf::SegmentStats st;
  t.restart();
  cf::MaskImage::Pointer mask = cf::segment_colon(ct, {}, &st);
  const double seg_s = t.seconds();
  std::printf("%7zu %7.2f %7.2f %7.2f %5.1f %8.0f %9.1f %9.1f %7d %9.1f %s (%s)\n", ct->GetLargestPossibleRegion().GetSize()[2],
              read_s, seg_s, st.cpu_time_s, load, cf::peak_memory_mib(), st.lumen_volume_ml, st.fluid_volume_ml, st.segments,
              st.tagged_stretch_volume_ml, st.gravity.c_str(), st.gravity_source.c_str());
  std::printf("columns: peak_MiB = peak resident memory of reading (and padding) + segmentation; fluid_mL = kept voxels >= "
              "--fluid-threshold; tagged_mL = fully tagged stretches kept by linking\n");
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
  bool table_only = false, dicom = true, collapsed = false, realistic = false, painted = false, seeds_given = false;
  int pad_to = 0, downsample = 1;
  std::string mask_file = std::string(COLONFLAT_SHARED_DIR) + "/real/ctc_lumen_mask_a.nii.gz";
  std::string size = "full", real, cases, keep;
  std::vector<int> seeds = {1, 2, 3, 4, 5};
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--table-only") table_only = true;
    else if (a == "--no-dicom") dicom = false;
    else if (a == "--collapsed") collapsed = true;
    else if (a == "--realistic") realistic = true;
    else if (a == "--painted") painted = true;
    else if (a == "--mask" && i + 1 < argc) mask_file = argv[++i];
    else if (a == "--cases" && i + 1 < argc) cases = argv[++i];
    else if (a == "--keep" && i + 1 < argc) keep = argv[++i];
    else if (a == "--downsample" && i + 1 < argc) downsample = std::stoi(argv[++i]);
    else if (a == "--real" && i + 1 < argc) real = argv[++i];
    else if (a == "--pad-to" && i + 1 < argc) pad_to = std::stoi(argv[++i]);
    else if (a == "--size" && i + 1 < argc) size = argv[++i];
    else if (a == "--seeds" && i + 1 < argc) {
      seeds.clear();
      seeds_given = true;
      std::stringstream s(argv[++i]);
      for (std::string x; std::getline(s, x, ',');) seeds.push_back(std::stoi(x));
    } else rest.push_back(argv[i]);
  }
  if (painted) painted_table(mask_file, downsample, cases, seeds_given ? seeds : std::vector<int>{1}, keep);
  else if (!real.empty()) real_table(real, pad_to);
  else if (realistic) realistic_table(size, seeds, pad_to);
  else table(size, seeds, dicom, collapsed);
  if (table_only) return 0;
  int n = int(rest.size());
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
