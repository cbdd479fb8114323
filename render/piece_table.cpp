#include "render/piece_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sim/rng.hpp"

namespace wingman::render {

namespace {

constexpr int N = PieceTable::kSize;

// The grid's vertex (i, j) sits at cell * (i + j / 2, j sqrt(3) / 2) (kStochasticLookup's lattice).
struct Offset {
  int di, dj;
  double x, y;  // at(vertex + offset) - at(vertex)
};

std::vector<Offset> neighbourhood(double cell) {
  std::vector<Offset> out;
  const int reach = static_cast<int>(std::ceil(2 * PieceTable::kRadiusCells)) + 1;
  for (int dj = -reach; dj <= reach; ++dj)
    for (int di = -reach; di <= reach; ++di) {
      const double x = cell * (di + 0.5 * dj), y = cell * 0.8660254037844386 * dj;
      if ((di != 0 || dj != 0) && std::hypot(x, y) <= PieceTable::kRadiusCells * cell + 1e-12)
        out.push_back({di, dj, x, y});
    }
  return out;
}

int wrap(int k) { return ((k % N) + N) % N; }

struct Sampler {
  PieceTable& t;
  std::mt19937_64 rng;
  double lo;

  double unit() { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
  void draw(double& u, double& v) {
    u = lo + unit() * (1 - 2 * lo);
    v = lo + unit() * (t.aspect - 2 * lo);
  }
};

Sampler sampler(PieceTable& t, double cell, double aspect, std::uint64_t seed) {
  if (!(cell > 0) || !(aspect > 0) || 2.04 * cell >= std::min(1.0, aspect))
    throw std::invalid_argument("piece_table: the cell must be positive and under half the image's shorter side");
  t.cell = cell;
  t.aspect = aspect;
  t.centres.assign(2 * N * N, 0.f);
  return {t, sim::make_stream(seed, "ground_tiling"), 1.02 * cell};
}

// The nearest copy between vertex (i, j) with centre (u, v) and the vertices set so far around it.
double nearest_copy(const PieceTable& t, const std::vector<Offset>& around, const std::vector<bool>& set, int i,
                    int j, double u, double v) {
  double best = std::numeric_limits<double>::infinity();
  const double overlap = 2 * t.cell;
  for (const Offset& o : around) {
    const int k = wrap(j + o.dj) * N + wrap(i + o.di);
    if (!set[static_cast<std::size_t>(k)]) continue;
    const double du = u - t.centres[2 * k], dv = v - t.centres[2 * k + 1];
    if (du * du + dv * dv >= overlap * overlap) continue;  // the pieces share no image point
    best = std::min(best, std::hypot(du + o.x, dv + o.y));
  }
  return best;
}

}  // namespace

void PieceTable::centre(int i, int j, double& u, double& v) const {
  const std::size_t k = static_cast<std::size_t>(wrap(j) * N + wrap(i));
  u = centres[2 * k];
  v = centres[2 * k + 1];
}

PieceTable piece_table(double cell, double aspect, std::uint64_t seed) {
  PieceTable t;
  Sampler s = sampler(t, cell, aspect, seed);
  const std::vector<Offset> around = neighbourhood(cell);
  std::vector<bool> set(static_cast<std::size_t>(N * N), false);
  // Sweeps over the table: the first fills it, the later ones revisit each vertex against all of
  // its neighbours (the first sweep saw only those before it), keeping its centre unless a
  // candidate moves its nearest copy farther away.
  for (int sweep = 0; sweep < PieceTable::kSweeps; ++sweep)
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i) {
        const std::size_t k = static_cast<std::size_t>(j * N + i);
        double bu = t.centres[2 * k], bv = t.centres[2 * k + 1];
        double best = set[k] ? nearest_copy(t, around, set, i, j, bu, bv) : -1;
        for (int c = 0; c < PieceTable::kCandidates; ++c) {
          double u, v;
          s.draw(u, v);
          const double d = nearest_copy(t, around, set, i, j, u, v);
          if (d > best) best = d, bu = u, bv = v;
        }
        t.centres[2 * k] = static_cast<float>(bu);
        t.centres[2 * k + 1] = static_cast<float>(bv);
        set[k] = true;
      }
  return t;
}

PieceTable random_piece_table(double cell, double aspect, std::uint64_t seed) {
  PieceTable t;
  Sampler s = sampler(t, cell, aspect, seed);
  for (std::size_t k = 0; k < static_cast<std::size_t>(N * N); ++k) {
    double u, v;
    s.draw(u, v);
    t.centres[2 * k] = static_cast<float>(u);
    t.centres[2 * k + 1] = static_cast<float>(v);
  }
  return t;
}

double min_copy_distance(const PieceTable& t) {
  const std::vector<Offset> around = neighbourhood(t.cell);
  const std::vector<bool> set(static_cast<std::size_t>(N * N), true);
  double worst = std::numeric_limits<double>::infinity();
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      double u, v;
      t.centre(i, j, u, v);
      worst = std::min(worst, nearest_copy(t, around, set, i, j, u, v));
    }
  return worst;
}

}  // namespace wingman::render
