#include "colonflat/denoise/vertex_adjacency.h"

#include <algorithm>

#include "colonflat/core/huge_pages.h"
#include "colonflat/denoise/surgery.h"

namespace cf {

namespace {

// Room for the lists that surgeries write again before the next rebuild (in stored entries per
// live one): a rebuild once the stale entries outgrow it.
constexpr double kStaleRoom = 0.25;

}  // namespace

void VertexAdjacency::append(const Mesh& mesh, int v) {
  const auto vh = Mesh::VertexHandle(v);
  const Vec3& pv = mesh.point(vh);
  const auto begin = static_cast<std::uint32_t>(out_.size());
  for (auto h : mesh.voh_range(vh)) {
    const auto w = mesh.to_vertex_handle(h);
    out_.push_back(Out{w.idx(), h.idx(), (mesh.point(w) - pv).norm()});  // the walks' own expression
  }
  span_[std::size_t(v)] = {begin, static_cast<std::uint32_t>(out_.size())};
  live_ += out_.size() - begin;
}

// Writes the lists of vertices [from, to) at their spans' starts; false when a list is not as long as
// its span (a vertex whose outgoing halfedges are not all in its voh_range() ring).
bool VertexAdjacency::fill(const Mesh& mesh, std::size_t from, std::size_t to) {
  for (std::size_t v = from; v < to; ++v) {
    const auto vh = Mesh::VertexHandle(static_cast<int>(v));
    const Vec3& pv = mesh.point(vh);
    std::uint32_t i = span_[v].first;
    for (auto h : mesh.voh_range(vh)) {
      if (i == span_[v].second) return false;
      const auto w = mesh.to_vertex_handle(h);
      out_[i++] = Out{w.idx(), h.idx(), (mesh.point(w) - pv).norm()};  // the walks' own expression
    }
    if (i != span_[v].second) return false;
  }
  return true;
}

void VertexAdjacency::build(const Mesh& mesh, const RunBoth& run_both) {
  const std::size_t n = mesh.n_vertices(), halfedges = mesh.n_halfedges();
  out_.clear();
  // Every halfedge once, the stale room beyond (a fresh block: advised before it is written).
  const std::size_t room = halfedges + static_cast<std::size_t>(kStaleRoom * double(halfedges));
  if (out_.capacity() < room) {
    decltype(out_) fresh;
    fresh.reserve(room);
    if (room * sizeof(Out) >= kHugePageMinBytes) advise_huge_pages(fresh.data(), room * sizeof(Out));
    out_.swap(fresh);
  }
  span_.assign(n, {0, 0});
  for (std::size_t h = 0; h < halfedges; ++h)  // out-degrees, in one pass over the halfedges
    ++span_[std::size_t(mesh.from_vertex_handle(Mesh::HalfedgeHandle(static_cast<int>(h))).idx())].second;
  std::uint32_t at = 0;
  for (auto& [first, last] : span_) {
    first = at;
    last = at += last;
  }
  out_.resize(halfedges);
  live_ = halfedges;
  bool ok[2] = {true, true};
  if (run_both) run_both([&] { ok[0] = fill(mesh, 0, n / 2); }, [&] { ok[1] = fill(mesh, n / 2, n); });
  else ok[0] = fill(mesh, 0, n);
  if (ok[0] && ok[1]) return;
  out_.clear();  // a ring that misses some outgoing halfedge: each vertex's list as its walk gives it
  live_ = 0;
  for (std::size_t v = 0; v < n; ++v) append(mesh, static_cast<int>(v));
}

void VertexAdjacency::refresh(const Mesh& mesh, const std::vector<int>& vertices) {
  const std::size_t n = mesh.n_vertices();
  const std::size_t known = std::min(span_.size(), n);
  for (std::size_t v = known; v < span_.size(); ++v) live_ -= span_[v].second - span_[v].first;  // removed
  span_.resize(n, {0, 0});
  const auto rewrite = [&](std::size_t v) {
    live_ -= span_[v].second - span_[v].first;
    append(mesh, static_cast<int>(v));
  };
  for (int v : vertices)
    if (v >= 0 && std::size_t(v) < known) rewrite(std::size_t(v));
  for (std::size_t v = known; v < n; ++v) rewrite(v);  // added
  if (double(out_.size()) > (1.0 + kStaleRoom) * double(live_) + 4096.0) build(mesh);
}

std::vector<int> touched_by_surgery(const Mesh& mesh, const SurgeryUndo& undo) {
  std::vector<int> t;
  const auto ends = [&](Mesh::HalfedgeHandle h) {
    t.push_back(mesh.from_vertex_handle(h).idx());
    t.push_back(mesh.to_vertex_handle(h).idx());
  };
  for (std::size_t v = undo.vertices; v < mesh.n_vertices(); ++v) t.push_back(static_cast<int>(v));
  for (std::size_t h = 2 * undo.edges; h < mesh.n_halfedges(); ++h) ends(Mesh::HalfedgeHandle(static_cast<int>(h)));
  for (std::size_t f = undo.faces; f < mesh.n_faces(); ++f)
    for (auto v : mesh.fv_range(Mesh::FaceHandle(static_cast<int>(f)))) t.push_back(v.idx());
  for (const auto& [h, old_to] : undo.targets) {
    ends(h);
    t.push_back(old_to.idx());
  }
  for (const auto& [f, cycle] : undo.face_cycles)
    for (auto h : cycle) ends(h);
  for (const auto& [v, h] : undo.vertex_halfedges) t.push_back(v.idx());
  for (const auto& [v, p] : undo.positions) {
    t.push_back(v.idx());
    for (auto w : mesh.vv_range(v)) t.push_back(w.idx());
  }
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

}  // namespace cf
