#include "stages/report/wall_snapshot.h"
#include "common/geometry/angles.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Eigenvalues>

namespace tiltcal::report {
namespace {

// First and second moments of the points of a cell (or of a cluster).
struct Moments {
  int64_t n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();

  void Add(const Eigen::Vector3d& p) {
    ++n;
    sum += p;
    sum_outer += p * p.transpose();
  }
  void Add(const Moments& m) {
    n += m.n;
    sum += m.sum;
    sum_outer += m.sum_outer;
  }
  Eigen::Vector3d Centroid() const { return sum / static_cast<double>(n); }
  // Eigenvalues ascending (l3, l2, l1) and the eigenvectors of the scatter.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> Scatter() const {
    const Eigen::Vector3d c = Centroid();
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
        sum_outer / static_cast<double>(n) - c * c.transpose());
  }
};

struct Cell {
  Eigen::Vector3i index;
  Moments moments;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  bool wall = false;
  int cluster = -1;
};

// 21 bits per axis: cell indices in [-2^20, 2^20).
constexpr int64_t kKeyOffset = int64_t{1} << 20;
int64_t Key(const Eigen::Vector3i& i) {
  return ((i.x() + kKeyOffset) << 42) | ((i.y() + kKeyOffset) << 21) | (i.z() + kKeyOffset);
}

// The cell of `p`, or nullopt when p is not finite or its cell or a
// neighbour of it would be outside the keys' range (|index| < 2^20 - 1;
// with 1 m cells, beyond about 1000 km from the origin of frame a).
std::optional<Eigen::Vector3i> CellOf(const Eigen::Vector3d& p, double cell_m) {
  const Eigen::Array3d index = (p / cell_m).array().floor();
  constexpr double kLimit = static_cast<double>(kKeyOffset - 1);
  if (!index.allFinite() || (index.abs() >= kLimit).any()) return std::nullopt;
  return index.cast<int>().matrix();
}

// The points binned into cells of cell_m, and each cell's index in `cells`
// by Key.
struct CellGrid {
  std::unordered_map<int64_t, size_t> index_of;
  std::vector<Cell> cells;
};

CellGrid BinIntoCells(const std::vector<Eigen::Vector3f>& points, double cell_m) {
  CellGrid grid;
  for (const Eigen::Vector3f& q : points) {
    const Eigen::Vector3d p = q.cast<double>();
    const std::optional<Eigen::Vector3i> cell_index = CellOf(p, cell_m);
    if (!cell_index) continue;  // not finite, or beyond the cell grid
    const Eigen::Vector3i& i = *cell_index;
    const auto [it, inserted] = grid.index_of.emplace(Key(i), grid.cells.size());
    if (inserted) {
      Cell cell;
      cell.index = i;
      grid.cells.push_back(cell);
    }
    grid.cells[it->second].moments.Add(p);
  }
  return grid;
}

// A cell of enough points is a wall cell when planar and vertical.
void MarkWallCells(const Eigen::Vector3d& up, const proto::WallSnapshotParams& params,
                   std::vector<Cell>* cells) {
  for (Cell& cell : *cells) {
    if (cell.moments.n < static_cast<int64_t>(params.min_cell_points())) continue;
    const auto scatter = cell.moments.Scatter();
    const Eigen::Vector3d l = scatter.eigenvalues();
    cell.centroid = cell.moments.Centroid();
    cell.normal = scatter.eigenvectors().col(0);
    cell.wall = l.y() > 0 && l.x() / l.y() < params.max_cell_planarity() &&
                std::abs(cell.normal.dot(up)) < params.max_normal_up();
  }
}

// Region growing over the wall cells: neighbours (26-connected) with
// parallel normals, each within max_plane_distance_m of the other's plane.
// Sets each cell's cluster; the clusters' moments and cell counts.
void GrowWallClusters(const proto::WallSnapshotParams& params, CellGrid* grid,
                      std::vector<Moments>* clusters, std::vector<int>* cluster_cells) {
  std::vector<Cell>& cells = grid->cells;
  const double min_cos = std::cos(geometry::DegToRad(params.max_normal_angle_deg()));
  for (size_t seed = 0; seed < cells.size(); ++seed) {
    if (!cells[seed].wall || cells[seed].cluster >= 0) continue;
    const int id = static_cast<int>(clusters->size());
    clusters->emplace_back();
    cluster_cells->push_back(0);
    std::vector<size_t> stack = {seed};
    cells[seed].cluster = id;
    while (!stack.empty()) {
      const Cell& cell = cells[stack.back()];
      stack.pop_back();
      (*clusters)[id].Add(cell.moments);
      ++(*cluster_cells)[id];
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = grid->index_of.find(Key(cell.index + Eigen::Vector3i(dx, dy, dz)));
            if (it == grid->index_of.end()) continue;
            Cell& next = cells[it->second];
            if (!next.wall || next.cluster >= 0) continue;
            const Eigen::Vector3d d = next.centroid - cell.centroid;
            if (std::abs(cell.normal.dot(next.normal)) < min_cos ||
                std::abs(cell.normal.dot(d)) > params.max_plane_distance_m() ||
                std::abs(next.normal.dot(d)) > params.max_plane_distance_m()) {
              continue;
            }
            next.cluster = id;
            stack.push_back(it->second);
          }
        }
      }
    }
  }
}

// The slab of cluster `best` (moments `wall`): its axes, and its height
// range from the cells' centroids grown by half a cell, at most
// max_height_m about its middle.
WallSlab SlabOfCluster(const std::vector<Cell>& cells, int best, const Moments& wall,
                       const Eigen::Vector3d& up, const proto::WallSnapshotParams& params) {
  WallSlab slab;
  slab.center = wall.Centroid();
  const Eigen::Vector3d normal = wall.Scatter().eigenvectors().col(0);
  slab.across = (normal - normal.dot(up) * up).normalized();
  slab.along = slab.across.cross(up).normalized();
  slab.up = slab.along.cross(slab.across);
  slab.length_m = params.slab_length_m();
  slab.depth_m = params.slab_depth_m();
  double low = 0.0, high = 0.0;
  bool first = true;
  for (const Cell& cell : cells) {
    if (cell.cluster != best) continue;
    const double h = slab.up.dot(cell.centroid - slab.center);
    low = first ? h : std::min(low, h);
    high = first ? h : std::max(high, h);
    first = false;
  }
  low -= 0.5 * params.cell_m();
  high += 0.5 * params.cell_m();
  const double middle = 0.5 * (low + high);
  const double half = 0.5 * std::min(high - low, params.max_height_m());
  slab.bottom_m = middle - half;
  slab.top_m = middle + half;
  return slab;
}

}  // namespace

std::optional<WallSlab> FindWall(const std::vector<Eigen::Vector3f>& points,
                                 const Eigen::Vector3d& up,
                                 const proto::WallSnapshotParams& params) {
  CellGrid grid = BinIntoCells(points, params.cell_m());
  MarkWallCells(up, params, &grid.cells);
  std::vector<Moments> clusters;
  std::vector<int> cluster_cells;
  GrowWallClusters(params, &grid, &clusters, &cluster_cells);
  if (clusters.empty()) return std::nullopt;
  const auto best = static_cast<int>(
      std::max_element(clusters.begin(), clusters.end(),
                       [](const Moments& a, const Moments& b) { return a.n < b.n; }) -
      clusters.begin());
  const Moments& wall = clusters[best];
  WallSlab slab = SlabOfCluster(grid.cells, best, wall, up, params);
  slab.cells = cluster_cells[best];
  slab.points = wall.n;
  return slab;
}

DensityImage RenderWallView(const std::vector<Eigen::Vector3f>& points, const WallSlab& slab,
                            WallView view, double pixels_per_m) {
  const double height_m = slab.top_m - slab.bottom_m;
  DensityImage image;
  image.width = static_cast<int>(
      std::lround((view == WallView::kTop ? slab.length_m : slab.depth_m) * pixels_per_m));
  image.height = static_cast<int>(
      std::lround((view == WallView::kTop ? slab.depth_m : height_m) * pixels_per_m));
  image.counts.assign(static_cast<size_t>(image.width) * image.height, 0);
  for (const Eigen::Vector3f& q : points) {
    const Eigen::Vector3d d = q.cast<double>() - slab.center;
    const double a = slab.along.dot(d) + 0.5 * slab.length_m;   // [0, length)
    const double b = 0.5 * slab.depth_m - slab.across.dot(d);   // [0, depth), +across on top
    const double h = slab.top_m - slab.up.dot(d);               // [0, height), top on top
    if (!(a >= 0 && a < slab.length_m && b >= 0 && b < slab.depth_m && h >= 0 &&
          h < height_m)) {
      continue;
    }
    const double column_m = view == WallView::kTop ? a : slab.depth_m - b;
    const double row_m = view == WallView::kTop ? b : h;
    const int column = std::min(image.width - 1, static_cast<int>(column_m * pixels_per_m));
    const int row = std::min(image.height - 1, static_cast<int>(row_m * pixels_per_m));
    ++image.counts[static_cast<size_t>(row) * image.width + column];
  }
  return image;
}

double WallSpread(const std::vector<Eigen::Vector3f>& points, const WallSlab& slab) {
  std::vector<double> across;
  for (const Eigen::Vector3f& q : points) {
    const Eigen::Vector3d d = q.cast<double>() - slab.center;
    const double a = slab.along.dot(d);
    const double b = slab.across.dot(d);
    const double h = slab.up.dot(d);
    if (std::abs(a) < 0.5 * slab.length_m && std::abs(b) < 0.5 * slab.depth_m &&
        h >= slab.bottom_m && h < slab.top_m) {
      across.push_back(b);
    }
  }
  if (across.empty()) return 0.0;
  auto median = [](std::vector<double>* v) {
    const auto middle = v->begin() + static_cast<std::ptrdiff_t>(v->size() / 2);
    std::nth_element(v->begin(), middle, v->end());
    return *middle;
  };
  const double m = median(&across);
  for (double& b : across) b = std::abs(b - m);
  return 1.4826 * median(&across);
}

GrayImage ShadeDensity(const DensityImage& density, uint32_t saturation) {
  GrayImage image;
  image.width = density.width;
  image.height = density.height;
  image.pixels.resize(density.counts.size());
  const double scale = 1.0 / std::log1p(std::max<uint32_t>(1, saturation));
  for (size_t i = 0; i < density.counts.size(); ++i) {
    const double darkness = std::min(1.0, std::log1p(density.counts[i]) * scale);
    image.pixels[i] = static_cast<uint8_t>(std::lround(255.0 * (1.0 - darkness)));
  }
  return image;
}

}  // namespace tiltcal::report
