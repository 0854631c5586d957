#pragma once
// The elimination orders of a colon segment's systems (flatten, internal): AMD's or nested
// dissection's (METIS), chosen by the segment's size and, below kNestedDissectionMinVertices, by
// what AMD's order costs. Defined in harmonic.cpp.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace cf::flat_detail {

using Tri = std::array<int, 3>;
struct Edges;

// AMD's elimination order of the vertices of the edge graph E (nv vertices); its restriction to part
// of the surface is one for that part (the annulus once the ends are opened).
std::vector<int> fill_reducing_vertex_order(const Edges& E, int nv);
// Nested dissection's (METIS) order of the vertex graph of the faces t (nv vertices, every corner
// < nv), built from the corners (vertex_graph, metis_order.h; without METIS called directly: from
// the unit Laplacian of build_edges(t)): about half the factorisation's operations of AMD's on a
// colon band, for about 5 x its ordering time (SpdSolver).
std::vector<int> nested_dissection_vertex_order(const std::vector<Tri>& t, int nv);
// A colon segment from this many vertices on has its systems on the whole band (the first conformal
// map, the re-solve after cutting side branches, the whole-band area correction, the balancing)
// solved in nested dissection order, computed beside the opening of its ends. Below it the ordering
// (~5 x AMD's time) costs about what it saves on a colon-like segment (a 94 k-vertex side branch: 4e8
// flops saved, ~0.3 s, for ~0.8 s of ordering, session 12), unless AMD's order costs more than
// kDissectionMinFlopsPerVertex.
constexpr std::size_t kNestedDissectionMinVertices = 200000;
// From kNestedDissectionMinVertices on, area-balanced map (the conformal map solves one system).
bool uses_dissection(std::size_t vertices, const std::string& map);
// Below it (area-balanced map), AMD's order costing more than this many factorisation operations per
// vertex is replaced by nested dissection's: METIS's ~6 us CPU per vertex at ~1.8e9 operations per
// CPU s, half of AMD's saved on >= 2 factorisations (docs/flatten.md, session 24).
constexpr double kDissectionMinFlopsPerVertex = 1e4;
struct SegmentOrder {  // a segment's elimination order; whether it is nested dissection's
  std::vector<int> order;
  bool nested = false;
};
// The elimination order of a segment below kNestedDissectionMinVertices (closed surface: E, nv
// vertices) for its first solve: AMD's, or METIS's when `measure` and AMD's costs more than
// kDissectionMinFlopsPerVertex (a long tube: AMD's order ends in a dense root).
SegmentOrder small_segment_vertex_order(const Edges& E, int nv, bool measure = false);

}  // namespace cf::flat_detail
