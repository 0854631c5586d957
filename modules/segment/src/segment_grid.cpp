// Voxel-grid helpers of the segmentation: dims, threads, connected components, box dilation and
// erosion, the 3 x 3 x 3 mean (slice by slice), line enumeration.
#include <itkBinaryImageToLabelMapFilter.h>
#include <itkLabelMap.h>
#include <itkLabelObject.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <mutex>
#include <new>
#include <thread>

#include <sys/mman.h>

#include "colonflat/core/box_dilation.h"
#include "colonflat/core/threads.h"
#include "segment_internal.h"

namespace cf::segment_detail {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kHugeMin = std::size_t(4) << 20;  // smaller blocks: the ordinary heap

// Freed blocks kept mapped for reuse while a BlockReuse scope is open (one per segmentation; the
// graph cut's workers allocate concurrently, hence the lock).
struct KeptBlocks {
  std::mutex mu;
  int scopes = 0;
  std::vector<std::pair<std::size_t, void*>> blocks;  // (mapped size, address), most recently freed last
  std::size_t bytes = 0;
  void release() {
    for (const auto& [size, p] : blocks) ::munmap(p, size);
    blocks.clear();
    bytes = 0;
  }
};
KeptBlocks& kept() {
  static KeptBlocks k;
  return k;
}
std::size_t mapped_size(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

// A kept block of exactly `size` bytes (the most recently freed), or nullptr after releasing them all.
void* take_kept(std::size_t size) {
  KeptBlocks& k = kept();
  std::lock_guard<std::mutex> lock(k.mu);
  for (auto it = k.blocks.rbegin(); it != k.blocks.rend(); ++it)
    if (it->first == size) {
      void* p = it->second;
      k.bytes -= size;
      k.blocks.erase(std::next(it).base());
      return p;
    }
  k.release();
  return nullptr;
}
}  // namespace

void* huge_page_alloc(std::size_t bytes) {
  if (bytes < kHugeMin) return ::operator new(bytes);
  const std::size_t size = mapped_size(bytes);
  if (void* p = take_kept(size)) return p;
  void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  ::madvise(p, size, MADV_HUGEPAGE);  // advice only: without transparent huge pages, 4 KiB pages
#endif
  return p;
}

void huge_page_free(void* p, std::size_t bytes) {
  if (!p) return;
  if (bytes < kHugeMin) return ::operator delete(p);
  const std::size_t size = mapped_size(bytes);
  KeptBlocks& k = kept();
  {
    std::lock_guard<std::mutex> lock(k.mu);
    if (k.scopes > 0) {
      k.blocks.emplace_back(size, p);
      k.bytes += size;
      return;
    }
  }
  ::munmap(p, size);
}

BlockReuse::BlockReuse() {
  std::lock_guard<std::mutex> lock(kept().mu);
  ++kept().scopes;
}

BlockReuse::~BlockReuse() {
  std::lock_guard<std::mutex> lock(kept().mu);
  if (--kept().scopes == 0) kept().release();
}

void release_kept_blocks() {
  std::lock_guard<std::mutex> lock(kept().mu);
  kept().release();
}

std::size_t kept_block_bytes() {
  std::lock_guard<std::mutex> lock(kept().mu);
  return kept().bytes;
}

void step_time(const char* name) {
  static const bool on = std::getenv("COLONFLAT_SEGMENT_TIMES") != nullptr;
  if (!on) return;
  static Stopwatch clock;
  static double cpu = process_cpu_seconds();
  const double now = process_cpu_seconds();
  std::fprintf(stderr, "segment step %s: wall %.3f s, cpu %.3f s\n", name, clock.lap(), now - cpu);
  cpu = now;
}

Dims make_dims(const std::size_t n[3], const double sp[3]) {
  Dims d;
  for (int a = 0; a < 3; ++a) {
    d.n[a] = n[a];
    d.sp[a] = sp[a];
  }
  d.stride[0] = 1;
  d.stride[1] = d.n[0];
  d.stride[2] = d.n[0] * d.n[1];
  d.total = d.n[0] * d.n[1] * d.n[2];
  return d;
}

void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body) {
  // One chunk per thread of cf::thread_count() (--threads): every caller computes each line, row or
  // slice the same way whichever chunk holds it, so results do not depend on the count.
  cf::parallel_for(n, body);
}

RunLabels component_runs(const unsigned char* mask, const Dims& d) {
  auto image = MaskImage::New();  // wraps `mask` without copying it
  image->SetRegions(MaskImage::SizeType{{d.n[0], d.n[1], d.n[2]}});
  auto container = MaskImage::PixelContainer::New();
  container->SetImportPointer(const_cast<unsigned char*>(mask), d.total, false);
  image->SetPixelContainer(container);
  using Map = itk::LabelMap<itk::LabelObject<std::uint32_t, 3>>;
  auto filter = itk::BinaryImageToLabelMapFilter<MaskImage, Map>::New();
  filter->SetInput(image);
  filter->SetFullyConnected(false);
  filter->SetInputForegroundValue(1);
  filter->SetOutputBackgroundValue(0);
  filter->SetNumberOfWorkUnits(2);
  filter->Update();
  const Map* map = filter->GetOutput();
  RunLabels out;
  const std::uint32_t n = std::uint32_t(map->GetNumberOfLabelObjects());
  out.first.reserve(n + 1);
  for (std::uint32_t l = 1; l <= n; ++l) {
    const auto* object = map->GetLabelObject(l);
    for (std::size_t i = 0, lines = object->GetNumberOfLines(); i < lines; ++i) {
      const auto& line = object->GetLine(i);
      const auto& at = line.GetIndex();
      out.runs.push_back({d.idx(std::size_t(at[0]), std::size_t(at[1]), std::size_t(at[2])), std::size_t(line.GetLength())});
    }
    out.first.push_back(out.runs.size());
  }
  return out;
}

std::vector<std::pair<Run, std::uint32_t>> RunLabels::raster(const std::vector<unsigned char>& keep) const {
  std::vector<std::pair<Run, std::uint32_t>> out;
  for (std::uint32_t l = 1; l <= count(); ++l)
    if (keep[l])
      for (const Run* r = begin(l); r != end(l); ++r) out.emplace_back(*r, l);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first.start < b.first.start; });
  return out;
}

void dilate_box(Bytes& v, const Dims& d, const int r[3]) { cf::dilate_box(v.data(), {d.n[0], d.n[1], d.n[2]}, r); }

void erode_box(Bytes& v, const Dims& d, const int r[3]) {
  for_each_voxel(v.size(), [&](std::size_t q) { v[q] = !v[q]; });
  dilate_box(v, d, r);
  for_each_voxel(v.size(), [&](std::size_t q) { v[q] = !v[q]; });
}

namespace {
// The x-then-y 3 x 3 box mean of slice k (edges clamped) into `out`; `tmp` holds the x pass.
template <class T>
void mean_xy(const T* in, const Dims& d, std::size_t k, float* tmp, float* out) {
  const std::size_t nx = d.n[0], ny = d.n[1];
  const T* plane = in + k * nx * ny;
  for (std::size_t j = 0; j < ny; ++j) {
    const T* mid = plane + j * nx;
    float* row = tmp + j * nx;
    for (std::size_t i = 0; i < nx; ++i)  // a sum of integer-valued floats is the int sum: exact below 2^24
      row[i] = float(mid[i > 0 ? i - 1 : i] + mid[i] + mid[i + 1 < nx ? i + 1 : i]) * (1.0f / 3.0f);
  }
  for (std::size_t j = 0; j < ny; ++j) {
    const float* mid = tmp + j * nx;
    const float* lo = j > 0 ? mid - nx : mid;
    const float* hi = j + 1 < ny ? mid + nx : mid;
    float* row = out + j * nx;
    for (std::size_t i = 0; i < nx; ++i) row[i] = (lo[i] + mid[i] + hi[i]) * (1.0f / 3.0f);
  }
}

template <class T>
void box_mean3_slices_of(const T* in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice) {
  const std::size_t plane = d.n[0] * d.n[1], nz = d.n[2];
  parallel_for(nz, [&](std::size_t k0, std::size_t k1) {
    if (k0 >= k1) return;
    std::vector<float> tmp(plane), mean(plane), lo(plane), mid(plane), hi(plane);
    mean_xy(in, d, k0 > 0 ? k0 - 1 : 0, tmp.data(), lo.data());
    mean_xy(in, d, k0, tmp.data(), mid.data());
    for (std::size_t k = k0; k < k1; ++k) {
      mean_xy(in, d, std::min(k + 1, nz - 1), tmp.data(), hi.data());
      for (std::size_t q = 0; q < plane; ++q) mean[q] = (lo[q] + mid[q] + hi[q]) * (1.0f / 3.0f);
      slice(k, mean.data());
      lo.swap(mid);
      mid.swap(hi);
    }
  });
}
}  // namespace

void box_mean3_slices(const float* in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice) {
  box_mean3_slices_of(in, d, slice);
}

void box_mean3_slices(const std::int16_t* in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice) {
  box_mean3_slices_of(in, d, slice);
}

void box_mean3_slices(const HuCrop& in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice) {
  if (in.narrow()) box_mean3_slices_of(in.narrow_data(), d, slice);
  else box_mean3_slices_of(in.wide_data(), d, slice);
}

RunLookup::RunLookup(const RunLabels& labels) {
  for (const auto& [run, label] : labels.raster(std::vector<unsigned char>(labels.count() + 1, 1))) {
    start_.push_back(run.start);
    length_.push_back(run.length);
    label_.push_back(label);
  }
}

std::uint32_t RunLookup::at(std::size_t q) const {
  const auto it = std::upper_bound(start_.begin(), start_.end(), q);
  if (it == start_.begin()) return 0;
  const std::size_t r = std::size_t(it - start_.begin()) - 1;
  return q < start_[r] + length_[r] ? label_[r] : 0;
}

std::size_t line_base(const Dims& d, int ax, std::size_t l) {
  if (ax == 0) return l * d.n[0];
  if (ax == 1) return (l % d.n[0]) + (l / d.n[0]) * d.n[0] * d.n[1];
  return l;
}

}  // namespace cf::segment_detail
