// The strips of the minimum-cut caps (step 7f, surgery_mincut.cpp): each ring joined to its cap's
// rim by a band of triangles that advance along the ring or the rim one edge at a time. The
// least-area band is found by dynamic programming (contour tiling); a band triangle that meets the
// surface, a cap's disk or another band triangle (right or left: the left band is the right one's
// mirror) is forbidden and the band found again, up to kStripRounds times (session 32: on the raw
// CT mask's loop 91 the least-area band folded over the disk's squares at a smoothed rim corner,
// and without the smoothing it met a wall).
#include <algorithm>
#include <unordered_map>

#include "colonflat/denoise/face_grid.h"
#include "surgery_steps.h"
#include "triangle_hash.h"

namespace cf::detail {

namespace {
constexpr int kStripRounds = 16;
}  // namespace

// The strip between `ring` (mesh vertices, loop order) and `inner` (the disk's boundary, loop
// direction), oriented like the ring: the least-area one that joins ring[0] to the inner vertex
// nearest it, advances along one side per triangle and uses no triangle `forbidden` marks
// (index 2 c + 1 for the triangle that reaches table cell c = i (m + 1) + j along the ring, 2 c along
// the rim). *keys receives each triangle's index. False when every strip uses a forbidden one.
bool Surgery::mincut_strip(const std::vector<Mesh::VertexHandle>& ring, const std::vector<int>& inner,
                           const std::vector<char>& forbidden, std::vector<std::array<int, 3>>* tris,
                           std::vector<std::size_t>* keys) const {
  const std::size_t k = ring.size(), m = inner.size();
  auto at = [this](int v) { return mesh_.point(Mesh::VertexHandle(v)); };
  std::size_t j0 = 0;
  for (std::size_t j = 1; j < m; ++j)
    if ((at(inner[j]) - mesh_.point(ring[0])).sqrnorm() < (at(inner[j0]) - mesh_.point(ring[0])).sqrnorm()) j0 = j;
  auto r = [&](std::size_t i) { return ring[i % k].idx(); };
  auto b = [&](std::size_t j) { return inner[(j0 + j) % m]; };
  auto area = [&](int x, int y, int z) { return OpenMesh::cross(at(y) - at(x), at(z) - at(x)).norm(); };
  const std::size_t w = m + 1;
  std::vector<double> cost((k + 1) * w, 1e300);
  std::vector<char> along_ring((k + 1) * w, 0);
  cost[0] = 0;
  for (std::size_t i = 0; i <= k; ++i)
    for (std::size_t j = 0; j <= m; ++j) {
      const std::size_t c = i * w + j;
      if (i > 0 && !forbidden[2 * c + 1] && cost[c - w] + area(r(i - 1), r(i), b(j)) < cost[c]) {
        cost[c] = cost[c - w] + area(r(i - 1), r(i), b(j));
        along_ring[c] = 1;
      }
      if (j > 0 && !forbidden[2 * c] && cost[c - 1] + area(r(i), b(j), b(j - 1)) < cost[c]) {
        cost[c] = cost[c - 1] + area(r(i), b(j), b(j - 1));
        along_ring[c] = 0;
      }
    }
  if (cost[k * w + m] >= 1e300) return false;
  std::vector<std::array<int, 3>> back;
  std::vector<std::size_t> back_keys;
  for (std::size_t i = k, j = m; i > 0 || j > 0;) {
    const std::size_t c = i * w + j;
    back_keys.push_back(2 * c + along_ring[c]);
    if (along_ring[c]) back.push_back({r(i - 1), r(i), b(j)}), --i;
    else back.push_back({r(i), b(j), b(j - 1)}), --j;
  }
  tris->assign(back.rbegin(), back.rend());
  keys->assign(back_keys.rbegin(), back_keys.rend());
  return true;
}

// Both strips: the right ring to `inner` (the right cap's rim, loop direction) and its mirror
// (`mirror`: right ring and right cap vertex ids to the left's), with no triangle that meets the
// surface (the guard), `disks` (both caps' other triangles) or another strip triangle. False when
// kStripRounds rounds of forbidding the failed triangles leave none.
bool Surgery::mincut_strips(const std::vector<int>& inner, const std::unordered_map<int, int>& mirror,
                            const TriangleHash& disks, double cell, std::vector<std::array<int, 3>>* right,
                            std::vector<std::array<int, 3>>* left, std::vector<int>* disk_hits) const {
  std::vector<char> forbidden(2 * (k_ + 1) * (inner.size() + 1), 0);
  for (int round = 0; round < kStripRounds; ++round) {
    std::vector<std::size_t> keys;
    if (!mincut_strip(result_.right_ring, inner, forbidden, right, &keys)) return false;
    left->clear();
    for (const auto& t : *right) left->push_back({mirror.at(t[0]), mirror.at(t[2]), mirror.at(t[1])});
    const std::vector<std::size_t> bad = failed_strip_triangles(*right, *left, disks, cell, disk_hits);
    if (bad.empty()) return true;
    if (!disk_hits->empty()) return false;
    for (std::size_t t : bad) forbidden[keys[t]] = 1;
  }
  return false;
}

// The indices (in `right`) of the strip triangles whose right or left (mirrored) copy meets the
// surface, `disks` or another strip triangle.
std::vector<std::size_t> Surgery::failed_strip_triangles(const std::vector<std::array<int, 3>>& right,
                                                         const std::vector<std::array<int, 3>>& left,
                                                         const TriangleHash& disks, double cell,
                                                         std::vector<int>* disk_hits) const {
  TriangleHash strips(mesh_, 2 * cell);
  std::vector<std::size_t> bad;
  const std::size_t n = right.size();
  for (std::size_t i = 0; i < 2 * n; ++i) {
    const auto& t = i < n ? right[i] : left[i - n];
    const int other = strips.crossing(t);
    if (other >= 0) bad.push_back(std::size_t(other) % n);
    const int dk = disks.crossing(t);
    if (dk >= 0) disk_hits->push_back(dk);
    if (other >= 0 || dk >= 0 || opts_.guard->hits(mesh_, t)) bad.push_back(i % n);
    strips.insert(t);
  }
  return bad;
}

}  // namespace cf::detail
