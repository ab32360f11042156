// Constrained Delaunay triangulation through CGAL (paper Sec. 4 "Enriching
// the coarse mesh"; thesis 2.3.2: the samples of a flat region are connected
// by Delaunay triangulation).
#include "crumple/mesh/delaunay.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_data_structure_2.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>

#include "crumple/core/index.hpp"

namespace crumple::mesh {
namespace {

struct VertexInfo {
  int index = -1;  // index into the input points; -1 for a vertex CGAL added itself
};
struct FaceInfo {
  int nesting = -1;  // constrained edges crossed from the infinite face; -1 = not visited
};

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using FaceBaseInfo = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>;
using FaceBase = CGAL::Constrained_triangulation_face_base_2<Kernel, FaceBaseInfo>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// Exact predicates, no exact constructions: an intersection of constraints
// would need a constructed point, which we detect and refuse.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using FaceHandle = Cdt::Face_handle;

std::string pointName(const std::vector<Vec2>& points, int i) {
  const Vec2& p = points[idx(i)];
  return "point " + std::to_string(i) + " (" + std::to_string(p.x()) + ", " +
         std::to_string(p.y()) + ")";
}

// Throws when two points are closer than 1e-12 times the bounding-box diagonal.
void rejectDuplicates(const std::vector<Vec2>& points) {
  if (points.size() < 2) return;
  Eigen::AlignedBox2d box;
  for (const Vec2& p : points) box.extend(p);
  const double eps = 1e-12 * box.diagonal().norm();
  std::vector<int> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const auto at = [&](int i) -> const Vec2& { return points[idx(i)]; };
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return at(a).x() != at(b).x() ? at(a).x() < at(b).x() : a < b; });
  for (std::size_t i = 0; i < order.size(); ++i)
    for (std::size_t j = i + 1; j < order.size() && at(order[j]).x() - at(order[i]).x() <= eps; ++j)
      if ((at(order[j]) - at(order[i])).norm() <= eps) {
        const int a = std::min(order[i], order[j]);
        const int b = std::max(order[i], order[j]);
        throw std::invalid_argument("constrainedDelaunay: duplicate points: " +
                                    pointName(points, a) + " and " + pointName(points, b));
      }
}

// Flood fill from `start` across unconstrained edges (CGAL "mark domains").
void markDomain(FaceHandle start, int nesting, std::deque<Cdt::Edge>& border, const Cdt& cdt) {
  std::deque<FaceHandle> queue{start};
  while (!queue.empty()) {
    const FaceHandle f = queue.front();
    queue.pop_front();
    if (f->info().nesting != -1) continue;
    f->info().nesting = nesting;
    for (int i = 0; i < 3; ++i) {
      const FaceHandle n = f->neighbor(i);
      if (n->info().nesting != -1) continue;
      if (cdt.is_constrained(Cdt::Edge(f, i)))
        border.emplace_back(f, i);
      else
        queue.push_back(n);
    }
  }
}

// Nesting level of every face: 0 outside, odd inside the constrained domain.
void markDomains(Cdt& cdt) {
  for (const FaceHandle f : cdt.all_face_handles()) f->info().nesting = -1;
  std::deque<Cdt::Edge> border;
  markDomain(cdt.infinite_face(), 0, border, cdt);
  while (!border.empty()) {
    const Cdt::Edge e = border.front();
    border.pop_front();
    const FaceHandle n = e.first->neighbor(e.second);
    if (n->info().nesting == -1) markDomain(n, e.first->info().nesting + 1, border, cdt);
  }
}

// The input point (other than a and b) lying on segment ab, or -1.
int pointOnSegment(const std::vector<Vec2>& points, int a, int b) {
  const Kernel::Point_2 pa(points[idx(a)].x(), points[idx(a)].y());
  const Kernel::Point_2 pb(points[idx(b)].x(), points[idx(b)].y());
  const Kernel::Segment_2 s(pa, pb);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (static_cast<int>(i) == a || static_cast<int>(i) == b) continue;
    if (s.has_on(Kernel::Point_2(points[i].x(), points[i].y()))) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

// Paper Sec. 4 / thesis 2.3.2: Delaunay triangulation of a flat region's samples.
std::vector<std::array<int, 3>> constrainedDelaunay(
    const std::vector<Vec2>& points, const std::vector<std::array<int, 2>>& constraints) {
  const int n = static_cast<int>(points.size());
  for (int i = 0; i < n; ++i)
    if (!points[idx(i)].allFinite())
      throw std::invalid_argument("constrainedDelaunay: point " + std::to_string(i) +
                                  " is not finite");
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const auto [a, b] = constraints[k];
    if (a < 0 || a >= n || b < 0 || b >= n)
      throw std::invalid_argument("constrainedDelaunay: constraint " + std::to_string(k) +
                                  " has an out-of-range point index");
    if (a == b)
      throw std::invalid_argument("constrainedDelaunay: constraint " + std::to_string(k) +
                                  " joins point " + std::to_string(a) + " to itself");
  }
  rejectDuplicates(points);

  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handles(points.size());
  FaceHandle hint;
  for (int i = 0; i < n; ++i) {
    const Vec2& p = points[idx(i)];
    const auto v = cdt.insert(Kernel::Point_2(p.x(), p.y()), hint);
    v->info().index = i;
    handles[idx(i)] = v;
    hint = v->face();
  }

  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const auto [a, b] = constraints[k];
    cdt.insert_constraint(handles[idx(a)], handles[idx(b)]);
    if (static_cast<int>(cdt.number_of_vertices()) != n)
      throw std::invalid_argument("constrainedDelaunay: constraint " + std::to_string(k) + " (" +
                                  std::to_string(a) + "-" + std::to_string(b) +
                                  ") crosses an earlier constraint");
  }
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const auto [a, b] = constraints[k];
    if (!cdt.is_edge(handles[idx(a)], handles[idx(b)])) {
      const int on = pointOnSegment(points, a, b);
      throw std::invalid_argument("constrainedDelaunay: constraint " + std::to_string(k) + " (" +
                                  std::to_string(a) + "-" + std::to_string(b) +
                                  ") passes through " +
                                  (on >= 0 ? pointName(points, on) : std::string("another point")));
    }
  }

  std::vector<std::array<int, 3>> triangles;
  if (cdt.dimension() < 2) return triangles;
  markDomains(cdt);
  for (const FaceHandle f : cdt.finite_face_handles()) {
    if (f->info().nesting % 2 != 1) continue;
    std::array<int, 3> t{f->vertex(0)->info().index, f->vertex(1)->info().index,
                         f->vertex(2)->info().index};
    // CGAL faces are counter-clockwise; start at the smallest index.
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    triangles.push_back(t);
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

}  // namespace crumple::mesh
