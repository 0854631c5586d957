// The segmentation's voxel-grid helpers against references: run labelling against
// itk::ConnectedComponentImageFilter, box dilation / erosion and the streamed 3 x 3 x 3 mean against
// brute force, on small random volumes.
#include <gtest/gtest.h>
#include <itkConnectedComponentImageFilter.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>

#include "../src/segment_internal.h"
#include "segment_dims.h"
#include "colonflat/core/threads.h"

namespace cf::segment_detail {
namespace {

Bytes random_mask(const Dims& d, double density, unsigned seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution on(density);
  Bytes m(d.total);
  for (auto& v : m) v = on(rng);
  return m;
}

// Run labels carry the same label per voxel as ITK's connected components (same numbering), for a
// mask with many irregular components.
TEST(SegmentGrid, RunLabelsMatchItkConnectedComponents) {
  const Dims d = unit_dims(37, 29, 23);
  const Bytes m = random_mask(d, 0.45, 7);
  auto image = MaskImage::New();
  image->SetRegions(MaskImage::SizeType{{d.n[0], d.n[1], d.n[2]}});
  image->Allocate();
  std::copy(m.begin(), m.end(), image->GetBufferPointer());
  auto cc = itk::ConnectedComponentImageFilter<MaskImage, itk::Image<std::uint32_t, 3>>::New();
  cc->SetInput(image);
  cc->SetFullyConnected(false);
  cc->SetNumberOfWorkUnits(2);
  cc->Update();
  const std::uint32_t* ref = cc->GetOutput()->GetBufferPointer();
  const RunLabels runs = component_runs(m.data(), d);
  ASSERT_EQ(runs.count(), cc->GetObjectCount());
  ASSERT_GT(runs.count(), 10u);
  std::vector<std::uint32_t> label(d.total, 0);
  for (std::uint32_t l = 1; l <= runs.count(); ++l)
    for (const segment_detail::Run* r = runs.begin(l); r != runs.end(l); ++r)
      for (std::size_t q = r->start; q < r->start + r->length; ++q) label[q] = l;
  for (std::size_t q = 0; q < d.total; ++q) ASSERT_EQ(label[q], ref[q]) << "voxel " << q;
}

// Dilates `m` and erodes `e` by the box of half-widths r and compares each voxel with the
// brute-force maximum / minimum over the box (clipped at the volume's faces).
void expect_box_matches_brute_force(const Dims& d, const Bytes& m, const Bytes& e, const int r[3]) {
  Bytes dil = m, ero = e;
  dilate_box(dil, d, r);
  erode_box(ero, d, r);
  for (std::size_t q = 0; q < d.total; ++q) {
    std::size_t c[3];
    d.coords(q, c[0], c[1], c[2]);
    bool any = false, all = true;
    for (long dk = -r[2]; dk <= r[2]; ++dk)
      for (long dj = -r[1]; dj <= r[1]; ++dj)
        for (long di = -r[0]; di <= r[0]; ++di) {
          const long i = long(c[0]) + di, j = long(c[1]) + dj, k = long(c[2]) + dk;
          if (i < 0 || j < 0 || k < 0 || i >= long(d.n[0]) || j >= long(d.n[1]) || k >= long(d.n[2])) continue;
          any = any || m[d.idx(i, j, k)];
          all = all && e[d.idx(i, j, k)];
        }
    ASSERT_EQ(bool(dil[q]), any) << "voxel " << q;
    ASSERT_EQ(bool(ero[q]), all) << "voxel " << q;
  }
}

// Box dilation (and erosion, its dual) equals the brute-force maximum over the box.
TEST(SegmentGrid, BoxDilationAndErosionMatchBruteForce) {
  const Dims d = unit_dims(31, 26, 19);
  const int r[3] = {2, 1, 3};
  expect_box_matches_brute_force(d, random_mask(d, 0.03, 11), random_mask(d, 0.9, 12), r);
}

// Radii of 255 voxels and more along y and z (beyond the byte distances of the fast sweep) and x
// (many doubling passes) give the brute-force box too (about one set voxel per line: partly covered
// lines), as does radius 254.
TEST(SegmentGrid, BoxDilationWithRadiusOver254MatchesBruteForce) {
  const Dims dx = unit_dims(300, 3, 6), dy = unit_dims(6, 300, 3), dz = unit_dims(6, 3, 300);
  const int rx[3] = {257, 0, 0}, ry[3] = {0, 260, 0}, rz[3] = {0, 0, 255}, r254[3] = {1, 254, 0};
  expect_box_matches_brute_force(dx, random_mask(dx, 0.002, 37), random_mask(dx, 0.998, 38), rx);
  expect_box_matches_brute_force(dy, random_mask(dy, 0.002, 31), random_mask(dy, 0.998, 32), ry);
  expect_box_matches_brute_force(dz, random_mask(dz, 0.002, 33), random_mask(dz, 0.998, 34), rz);
  expect_box_matches_brute_force(dy, random_mask(dy, 0.002, 35), random_mask(dy, 0.998, 36), r254);
}

// Ball erosion (anisotropic voxels 0.75 x 0.75 x 1.5 mm, radius 3 mm) equals the brute-force
// minimum over the ellipsoid of voxels within 3 mm, on a mask with holes and thin bridges.
TEST(SegmentGrid, BallErosionMatchesBruteForce) {
  const std::size_t n[3] = {34, 30, 22};
  const double sp[3] = {0.75, 0.75, 1.5};
  const Dims d = make_dims(n, sp);
  const Bytes m = random_mask(d, 0.985, 21);
  const Bytes e = erode_ball(m, d, 3.0);
  std::size_t set = 0;
  for (std::size_t q = 0; q < d.total; ++q) {
    std::size_t c[3];
    d.coords(q, c[0], c[1], c[2]);
    bool all = m[q] != 0;
    for (long dk = -2; dk <= 2; ++dk)
      for (long dj = -4; dj <= 4; ++dj)
        for (long di = -4; di <= 4; ++di) {
          const long i = long(c[0]) + di, j = long(c[1]) + dj, k = long(c[2]) + dk;
          if (i < 0 || j < 0 || k < 0 || i >= long(d.n[0]) || j >= long(d.n[1]) || k >= long(d.n[2])) continue;
          const double r2 = std::pow(di * 0.75, 2) + std::pow(dj * 0.75, 2) + std::pow(dk * 1.5, 2);
          if (r2 <= 9.0 + 1e-9) all = all && m[d.idx(i, j, k)];
        }
    ASSERT_EQ(bool(e[q]), all) << "voxel " << q;
    set += all;
  }
  EXPECT_GT(set, 20u);           // some voxels pass,
  EXPECT_LT(set, d.total / 2);  // most are within 3 mm of a hole
}

// Inside a BlockReuse scope a freed large block goes to the next request of its size with its pages
// as they were (not mapped and zeroed again: a fresh mapping reads 0), a request of another size
// releases every kept block before mapping (kept blocks never add to the peak), and closing the
// scope releases them; outside a scope nothing is kept.
TEST(SegmentGrid, FreedBlocksReusedInsideScopeReleasedOnMissAndAtEnd) {
  const std::size_t big = std::size_t(6) << 20;  // 3 huge pages: its mapped size is its size
  {
    BlockReuse scope;
    auto* a = static_cast<unsigned char*>(huge_page_alloc(big));
    std::memset(a, 0xAB, big);
    huge_page_free(a, big);
    EXPECT_EQ(kept_block_bytes(), big);
    auto* b = static_cast<unsigned char*>(huge_page_alloc(big));
    EXPECT_EQ(kept_block_bytes(), 0u);
    EXPECT_EQ(b, a);
    EXPECT_EQ(b[0], 0xAB);  // the same pages, not zeroed again
    EXPECT_EQ(b[big - 1], 0xAB);
    huge_page_free(b, big);
    void* c = huge_page_alloc(2 * big);  // no kept block of this size: all released first
    EXPECT_EQ(kept_block_bytes(), 0u);
    huge_page_free(c, 2 * big);
    EXPECT_EQ(kept_block_bytes(), 2 * big);
  }
  EXPECT_EQ(kept_block_bytes(), 0u);
  auto* d = static_cast<unsigned char*>(huge_page_alloc(big));
  std::memset(d, 0xCD, big);
  huge_page_free(d, big);
  EXPECT_EQ(kept_block_bytes(), 0u);
  auto* e = static_cast<unsigned char*>(huge_page_alloc(big));
  EXPECT_EQ(e[0], 0);  // a fresh mapping
  huge_page_free(e, big);
}

// A RawBuffer's resize writes nothing (a reused block keeps its bytes: no serial zeroing pass on the
// caller's thread), and fill_parallel then sets every element, for 1, 2 and 3 threads and when the
// size changes.
TEST(SegmentGrid, RawBufferResizeWritesNothingFillParallelSetsAll) {
  const std::size_t big = std::size_t(6) << 20;
  BlockReuse scope;
  auto* a = static_cast<unsigned char*>(huge_page_alloc(big));
  std::memset(a, 0xAB, big);
  huge_page_free(a, big);
  RawBuffer<std::uint32_t> v;
  v.resize(big / 4);
  ASSERT_EQ(static_cast<void*>(v.data()), static_cast<void*>(a));
  EXPECT_EQ(v.front(), 0xABABABABu);  // value-initialising resize would have written 0
  EXPECT_EQ(v.back(), 0xABABABABu);
  for (int t : {1, 2, 3}) {
    set_thread_count(t);
    fill_parallel(v, big / 4, std::uint32_t(t));
    EXPECT_EQ(std::count(v.begin(), v.end(), std::uint32_t(t)), std::ptrdiff_t(big / 4)) << t << " threads";
  }
  fill_parallel(v, big / 8 + 3, std::uint32_t(9));  // another size: a new block, every element written
  EXPECT_EQ(v.size(), big / 8 + 3);
  EXPECT_EQ(std::count(v.begin(), v.end(), 9u), std::ptrdiff_t(big / 8 + 3));
  set_thread_count(0);
}

// The streamed 3 x 3 x 3 mean equals the brute-force mean with clamped edges, every slice once.
TEST(SegmentGrid, StreamedBoxMeanMatchesBruteForce) {
  const Dims d = unit_dims(17, 13, 11);
  std::mt19937 rng(3);
  std::normal_distribution<float> hu(40, 300);
  std::vector<float> in(d.total);
  for (auto& v : in) v = hu(rng);
  std::vector<float> mean(d.total, NAN);
  std::vector<int> calls(d.n[2], 0);
  box_mean3_slices(in.data(), d, [&](std::size_t k, const float* slice) {
    ++calls[k];
    std::copy(slice, slice + d.n[0] * d.n[1], mean.begin() + long(k * d.n[0] * d.n[1]));
  });
  for (int c : calls) EXPECT_EQ(c, 1);
  auto clamp = [](long v, std::size_t n) { return std::size_t(std::min(std::max(v, 0L), long(n) - 1)); };
  for (std::size_t q = 0; q < d.total; ++q) {
    std::size_t c[3];
    d.coords(q, c[0], c[1], c[2]);
    double sum = 0;
    for (long dk = -1; dk <= 1; ++dk)
      for (long dj = -1; dj <= 1; ++dj)
        for (long di = -1; di <= 1; ++di)
          sum += in[d.idx(clamp(long(c[0]) + di, d.n[0]), clamp(long(c[1]) + dj, d.n[1]), clamp(long(c[2]) + dk, d.n[2]))];
    ASSERT_NEAR(mean[q], sum / 27.0, 1e-2) << "voxel " << q;
  }
}

}  // namespace
}  // namespace cf::segment_detail
