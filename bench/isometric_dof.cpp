// Why the crumpling model's isometry stalls: the isometric degrees of freedom
// S_P has left where it stalls, and whether an isometric S_P exists with its
// handles where the animation puts them (docs/CRUMPLING.md, "Why the
// isometry cannot close").
//
// For every requested frame the shot's last projection input (S_P as the
// crumpling model hands it to the isometry projection, paper Sec. 6.3) is
// captured and measured:
//  - first-order count: the rank of the edge-length Jacobian J (one row per
//    edge, d l_e / d x) over the free coordinates, with (a) nothing held
//    (minus the 6 rigid motions), (b) the handle vertices held, (c) the
//    handles and their tangent-plane pins held. 3 V_free - rank J is the
//    dimension of the first-order flexes; for a triangulated disc with B
//    boundary vertices the count predicts B - 3 with nothing held (E = 3V -
//    B - 3). A flat star (an interior vertex whose triangles are coplanar)
//    adds one flex that is infinitesimal only (it moves lengths to second
//    order), so the first-order count is an upper bound; the number of flat
//    stars bounds the spurious ones.
//  - finite test: a Levenberg-Marquardt solve of min sum_e ((l_e - L_e) /
//    L_e)^2 from the captured positions with the held vertices fixed, on S_P
//    as it is and on S_P refined once and twice by midpoint subdivision (in
//    the pattern and in space, so the refined sheet starts on the same
//    surface). If an isometric configuration with the handles where they are
//    exists near S_P, the solve finds it (c_mean -> 0); if it does not, the
//    residual measures how far the structure is from one (locking: English
//    & Bridson 2008; Goldenthal et al. 2007).
//
// Usage: bench_dof SCENE [--frames 42,60,90] [--model "key = value"]...
//        [--iterations 400]
#include <unistd.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/paper/hybrid_sheet.hpp"
#include "crumple/pipeline/shot.hpp"

namespace {

namespace fs = std::filesystem;
using crumple::Vec2;
using crumple::Vec3;
using Tri = std::array<int, 3>;

struct Capture {
  std::vector<Vec2> pattern;
  std::vector<Tri> triangles;
  std::vector<Vec3> positions;
  std::vector<int> handles;  // held by the projection
  std::vector<int> pinned;   // handles and tangent-plane pins
  int frame = 0;
};

struct Edges {
  std::vector<std::array<int, 2>> e;
  std::vector<double> rest;
  std::vector<char> boundaryVertex;
};

Edges buildEdges(const std::vector<Vec2>& pattern, const std::vector<Tri>& tris) {
  std::map<std::array<int, 2>, int> count;
  for (const Tri& t : tris)
    for (int k = 0; k < 3; ++k) {
      int a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
      if (a > b) std::swap(a, b);
      ++count[{a, b}];
    }
  Edges out;
  out.boundaryVertex.assign(pattern.size(), 0);
  for (const auto& [e, c] : count) {
    out.e.push_back(e);
    out.rest.push_back(
        (pattern[static_cast<std::size_t>(e[0])] - pattern[static_cast<std::size_t>(e[1])]).norm());
    if (c == 1)
      out.boundaryVertex[static_cast<std::size_t>(e[0])] =
          out.boundaryVertex[static_cast<std::size_t>(e[1])] = 1;
  }
  return out;
}

std::vector<int> usedVertices(const std::vector<Tri>& tris, std::size_t n) {
  std::vector<char> used(n, 0);
  for (const Tri& t : tris)
    for (int v : t) used[static_cast<std::size_t>(v)] = 1;
  std::vector<int> out;
  for (std::size_t i = 0; i < n; ++i)
    if (used[i]) out.push_back(static_cast<int>(i));
  return out;
}

// 3 V_free - rank J over the free coordinates (V counts vertices in a triangle).
int firstOrderFlexes(const Capture& c, const Edges& edges, const std::vector<int>& held) {
  const std::vector<int> used = usedVertices(c.triangles, c.pattern.size());
  std::vector<int> column(c.pattern.size(), -1);
  const std::set<int> heldSet(held.begin(), held.end());
  int free = 0;
  for (int v : used)
    if (heldSet.count(v) == 0) column[static_cast<std::size_t>(v)] = free++;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(edges.e.size()), 3 * free);
  for (std::size_t k = 0; k < edges.e.size(); ++k) {
    const auto [a, b] = edges.e[k];
    const Vec3 d =
        c.positions[static_cast<std::size_t>(b)] - c.positions[static_cast<std::size_t>(a)];
    const Vec3 u = d / d.norm();
    const auto row = static_cast<Eigen::Index>(k);
    if (const int ca = column[static_cast<std::size_t>(a)]; ca >= 0)
      J.block<1, 3>(row, 3 * ca) = -u.transpose();
    if (const int cb = column[static_cast<std::size_t>(b)]; cb >= 0)
      J.block<1, 3>(row, 3 * cb) = u.transpose();
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(J);
  const auto& s = svd.singularValues();
  const double tol = 1e-9 * std::max(1.0, s.size() > 0 ? s(0) : 1.0);
  int rank = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i) rank += s(i) > tol ? 1 : 0;
  return 3 * free - rank;
}

// Interior vertices whose triangles are coplanar within 0.01 rad.
int flatStars(const Capture& c, const Edges& edges) {
  std::vector<std::vector<int>> star(c.pattern.size());
  for (std::size_t t = 0; t < c.triangles.size(); ++t)
    for (int v : c.triangles[t]) star[static_cast<std::size_t>(v)].push_back(static_cast<int>(t));
  int flat = 0;
  for (std::size_t v = 0; v < star.size(); ++v) {
    if (star[v].empty() || edges.boundaryVertex[v]) continue;
    std::vector<Vec3> normals;
    for (int t : star[v]) {
      const Tri& tri = c.triangles[static_cast<std::size_t>(t)];
      const Vec3 n = (c.positions[static_cast<std::size_t>(tri[1])] -
                      c.positions[static_cast<std::size_t>(tri[0])])
                         .cross(c.positions[static_cast<std::size_t>(tri[2])] -
                                c.positions[static_cast<std::size_t>(tri[0])]);
      normals.push_back(n.normalized());
    }
    bool planar = true;
    for (const Vec3& n : normals) planar = planar && n.dot(normals[0]) > std::cos(0.01);
    flat += planar ? 1 : 0;
  }
  return flat;
}

// Midpoint subdivision, in the pattern and in space; old vertices keep their indices.
Capture refine(const Capture& c) {
  Capture out = c;
  out.triangles.clear();
  std::map<std::array<int, 2>, int> mid;
  const auto midpoint = [&](int a, int b) {
    std::array<int, 2> key{std::min(a, b), std::max(a, b)};
    if (auto it = mid.find(key); it != mid.end()) return it->second;
    const int v = static_cast<int>(out.pattern.size());
    out.pattern.push_back(
        0.5 * (c.pattern[static_cast<std::size_t>(a)] + c.pattern[static_cast<std::size_t>(b)]));
    out.positions.push_back(0.5 * (c.positions[static_cast<std::size_t>(a)] +
                                   c.positions[static_cast<std::size_t>(b)]));
    mid.emplace(key, v);
    return v;
  };
  for (const Tri& t : c.triangles) {
    const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

struct Lengths {
  double mean = 0.0, max = 0.0;
};

Lengths lengthErrors(const std::vector<Vec3>& x, const Edges& edges) {
  Lengths out;
  for (std::size_t k = 0; k < edges.e.size(); ++k) {
    const double l =
        (x[static_cast<std::size_t>(edges.e[k][1])] - x[static_cast<std::size_t>(edges.e[k][0])])
            .norm();
    const double err = std::abs(l - edges.rest[k]) / edges.rest[k];
    out.mean += err;
    out.max = std::max(out.max, err);
  }
  out.mean /= static_cast<double>(std::max<std::size_t>(1, edges.e.size()));
  return out;
}

// Levenberg-Marquardt on r_e = (l_e - L_e) / L_e with `held` fixed. Returns
// the lengths reached and the mean displacement of the free vertices.
Lengths closestIsometry(const Capture& c, const Edges& edges, const std::vector<int>& held,
                        int iterations, double* displacement) {
  const std::vector<int> used = usedVertices(c.triangles, c.pattern.size());
  std::vector<int> column(c.pattern.size(), -1);
  const std::set<int> heldSet(held.begin(), held.end());
  int free = 0;
  for (int v : used)
    if (heldSet.count(v) == 0) column[static_cast<std::size_t>(v)] = free++;
  std::vector<Vec3> x = c.positions;
  const auto cost = [&](const std::vector<Vec3>& p) {
    double s = 0.0;
    for (std::size_t k = 0; k < edges.e.size(); ++k) {
      const double l =
          (p[static_cast<std::size_t>(edges.e[k][1])] - p[static_cast<std::size_t>(edges.e[k][0])])
              .norm();
      const double r = (l - edges.rest[k]) / edges.rest[k];
      s += r * r;
    }
    return s;
  };
  double mu = 1e-3, f = cost(x);
  for (int it = 0; it < iterations && f > 1e-24; ++it) {
    std::vector<Eigen::Triplet<double>> trip;
    Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * free);
    for (std::size_t k = 0; k < edges.e.size(); ++k) {
      const auto [a, b] = edges.e[k];
      const Vec3 d = x[static_cast<std::size_t>(b)] - x[static_cast<std::size_t>(a)];
      const double l = d.norm();
      const double r = (l - edges.rest[k]) / edges.rest[k];
      const Vec3 u = d / (l * edges.rest[k]);  // d r / d x_b
      const std::array<int, 2> cols{column[static_cast<std::size_t>(a)],
                                    column[static_cast<std::size_t>(b)]};
      const std::array<double, 2> sign{-1.0, 1.0};
      for (int i = 0; i < 2; ++i) {
        if (cols[static_cast<std::size_t>(i)] < 0) continue;
        g.segment<3>(3 * cols[static_cast<std::size_t>(i)]) +=
            sign[static_cast<std::size_t>(i)] * r * u;
        for (int j = 0; j < 2; ++j) {
          if (cols[static_cast<std::size_t>(j)] < 0) continue;
          const Eigen::Matrix3d block = sign[static_cast<std::size_t>(i)] *
                                        sign[static_cast<std::size_t>(j)] * u * u.transpose();
          for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q)
              trip.emplace_back(3 * cols[static_cast<std::size_t>(i)] + p,
                                3 * cols[static_cast<std::size_t>(j)] + q, block(p, q));
        }
      }
    }
    Eigen::SparseMatrix<double> H(3 * free, 3 * free);
    H.setFromTriplets(trip.begin(), trip.end());
    bool accepted = false;
    for (int tries = 0; tries < 20 && !accepted; ++tries) {
      Eigen::SparseMatrix<double> A = H;
      for (int i = 0; i < 3 * free; ++i) A.coeffRef(i, i) += mu * (1.0 + H.coeff(i, i));
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
      if (ldlt.info() != Eigen::Success) {
        mu *= 10.0;
        continue;
      }
      const Eigen::VectorXd step = ldlt.solve(-g);
      std::vector<Vec3> trial = x;
      for (int v : used)
        if (const int cv = column[static_cast<std::size_t>(v)]; cv >= 0)
          trial[static_cast<std::size_t>(v)] += step.segment<3>(3 * cv);
      const double ft = cost(trial);
      if (ft < f) {
        x = std::move(trial);
        f = ft;
        mu = std::max(1e-12, mu / 3.0);
        accepted = true;
      } else {
        mu *= 4.0;
      }
    }
    if (!accepted) break;
  }
  if (displacement != nullptr) {
    double s = 0.0;
    int n = 0;
    for (int v : used)
      if (column[static_cast<std::size_t>(v)] >= 0) {
        s += (x[static_cast<std::size_t>(v)] - c.positions[static_cast<std::size_t>(v)]).norm();
        ++n;
      }
    *displacement = n > 0 ? s / n : 0.0;
  }
  return lengthErrors(x, edges);
}

std::vector<int> parseFrames(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stoi(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 2) {
      std::fprintf(stderr,
                   "usage: bench_dof SCENE [--frames A,B,...] [--model \"key = value\"]... "
                   "[--iterations N]\n");
      return 2;
    }
    std::string scenePath = crumple::io::resolveScenePath(argv[1]);
    std::vector<int> frames;
    std::string modelKeys;
    int iterations = 400;
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--frames" && i + 1 < argc) {
        frames = parseFrames(argv[++i]);
      } else if (a == "--model" && i + 1 < argc) {
        modelKeys += std::string(argv[++i]) + "\n";
      } else if (a == "--iterations" && i + 1 < argc) {
        iterations = std::stoi(argv[++i]);
      } else {
        std::fprintf(stderr, "bench_dof: unknown argument %s\n", a.c_str());
        return 2;
      }
    }
    std::ifstream in(scenePath);
    std::stringstream text;
    text << in.rdbuf();
    std::string toml = text.str();
    if (!modelKeys.empty()) {
      // Keys go into the scene's [model] table (appended as one when it has none).
      const auto at = toml.find("\n[model]");
      if (at == std::string::npos)
        toml += "\n[model]\n" + modelKeys;
      else
        toml.insert(toml.find('\n', at + 1) + 1, modelKeys);
    }
    const crumple::io::SceneSpec scene =
        crumple::io::parseScene(toml, scenePath, fs::path(scenePath).parent_path().string());
    std::map<int, Capture> captured;
    const std::set<int> wanted(frames.begin(), frames.end());
    crumple::pipeline::ShotOptions options;
    // One folder per process: runs side by side do not share it.
    options.outDir =
        (fs::temp_directory_path() / ("crumple-bench-dof-" + std::to_string(::getpid()))).string();
    options.render = false;
    options.log = nullptr;
    options.interactive = 0;
    options.projectionProbe = [&](const crumple::paper::ProjectionInput& p) {
      if (!wanted.empty() && wanted.count(p.frame) == 0) return;
      Capture& c = captured[p.frame];  // the frame's last animation step wins
      c.pattern = p.pattern;
      c.triangles = p.triangles;
      c.positions = p.positions;
      c.handles = p.fixed;
      c.pinned = p.pinned;
      c.frame = p.frame;
    };
    try {
      crumple::pipeline::runShot(scene, options);
    } catch (const crumple::NumericalError& e) {
      std::fprintf(stderr, "bench_dof: the shot stopped: %s (frames captured so far count)\n",
                   e.what());
    }
    std::error_code ec;
    fs::remove_all(options.outDir, ec);
    std::printf(
        "| frame | V | T | E | B | handles | pins | flat stars | flexes free-6 | flexes "
        "handles | flexes handles+pins | c_mean in | LM handles+pins | LM handles | LM handles, "
        "refined x4 (T) | LM handles, refined x16 (T) | LM one vertex |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& [frame, c] : captured) {
      const Edges edges = buildEdges(c.pattern, c.triangles);
      const std::vector<int> used = usedVertices(c.triangles, c.pattern.size());
      int boundary = 0;
      for (int v : used) boundary += edges.boundaryVertex[static_cast<std::size_t>(v)];
      const int flexNone = firstOrderFlexes(c, edges, {}) - 6;
      const int flexHandles = firstOrderFlexes(c, edges, c.handles);
      const int flexPins = firstOrderFlexes(c, edges, c.pinned);
      const Lengths start = lengthErrors(c.positions, edges);
      double dPins = 0, dHandles = 0, dOne = 0, d4 = 0, d16 = 0;
      const Lengths lmPins = closestIsometry(c, edges, c.pinned, iterations, &dPins);
      const Lengths lmHandles = closestIsometry(c, edges, c.handles, iterations, &dHandles);
      const Capture r4 = refine(c);
      const Edges e4 = buildEdges(r4.pattern, r4.triangles);
      const Lengths lm4 = closestIsometry(r4, e4, c.handles, iterations, &d4);
      const Capture r16 = refine(r4);
      const Edges e16 = buildEdges(r16.pattern, r16.triangles);
      const Lengths lm16 = closestIsometry(r16, e16, c.handles, iterations, &d16);
      const Lengths lmOne = closestIsometry(
          c, edges, std::vector<int>{c.handles.empty() ? used.front() : c.handles.front()},
          iterations, &dOne);
      const auto pct = [](const Lengths& l) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.3f / %.2f %%", 100.0 * l.mean, 100.0 * l.max);
        return std::string(buf);
      };
      std::printf(
          "| %d | %zu | %zu | %zu | %d | %zu | %zu | %d | %d | %d | %d | %s | %s | %s | %s (%zu) | "
          "%s (%zu) | %s |\n",
          frame, used.size(), c.triangles.size(), edges.e.size(), boundary, c.handles.size(),
          c.pinned.size(), flatStars(c, edges), flexNone, flexHandles, flexPins, pct(start).c_str(),
          pct(lmPins).c_str(), pct(lmHandles).c_str(), pct(lm4).c_str(), r4.triangles.size(),
          pct(lm16).c_str(), r16.triangles.size(), pct(lmOne).c_str());
      std::fflush(stdout);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_dof: %s\n", e.what());
    return 1;
  }
}
