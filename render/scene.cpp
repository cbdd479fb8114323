#include "render/scene.hpp"

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <algorithm>
#include <array>
#include <random>
#include <stdexcept>

#include "sim/assets.hpp"
#include "sim/rng.hpp"

namespace fs = std::filesystem;

namespace wingman::render {

void Mesh::add(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector2d& uv,
               const Eigen::Vector3d& c) {
  for (int i = 0; i < 3; ++i) {
    positions.push_back(static_cast<float>(p[i]));
    normals.push_back(static_cast<float>(n[i]));
    colours.push_back(static_cast<float>(c[i]));
  }
  uvs.push_back(static_cast<float>(uv[0]));
  uvs.push_back(static_cast<float>(uv[1]));
}

void Mesh::append(const Mesh& m) {
  const auto base = static_cast<std::uint32_t>(vertex_count());
  positions.insert(positions.end(), m.positions.begin(), m.positions.end());
  normals.insert(normals.end(), m.normals.begin(), m.normals.end());
  uvs.insert(uvs.end(), m.uvs.begin(), m.uvs.end());
  colours.insert(colours.end(), m.colours.begin(), m.colours.end());
  for (auto i : m.indices) indices.push_back(base + i);
}

namespace {

cv::Mat read_image_rgb(const std::string& path, const std::string& what) {
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) throw std::runtime_error(what + " '" + path + "': not an image OpenCV can read");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

// A seamless (periodic) noise layer: a random grid of `cells` x `cells`, smoothly upsampled.
cv::Mat periodic_noise(std::mt19937_64& rng, int size, int cells) {
  cells = std::max(2, std::min(cells, size));
  std::normal_distribution<float> n(0.f, 1.f);
  cv::Mat grid(cells, cells, CV_32F);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) grid.at<float>(r, c) = n(rng);
  const int pad = 2;
  cv::Mat padded;
  cv::copyMakeBorder(grid, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  const double cell_px = static_cast<double>(size) / cells;
  cv::Mat up;
  cv::resize(padded, up,
             cv::Size(static_cast<int>(std::lround(padded.cols * cell_px)),
                      static_cast<int>(std::lround(padded.rows * cell_px))),
             0, 0, cv::INTER_CUBIC);
  const int off = static_cast<int>(std::lround(pad * cell_px));
  return up(cv::Rect(off, off, size, size)).clone();
}

// Ground texture with detail from detail_min to detail_max: soil and grass patches at metre
// scale, modulated by fine noise down to one texel.
cv::Mat procedural_ground(const sim::TextureSpec& t, std::uint64_t seed) {
  auto rng = sim::make_stream(seed, "ground_texture");
  const int size = t.size;
  const double tile = size * t.detail_min;  // metres per tile
  cv::Mat patches = periodic_noise(rng, size, static_cast<int>(std::max(2.0, tile / 4.0)));
  cv::Mat fine = cv::Mat::zeros(size, size, CV_32F);
  double total = 0;
  for (double lambda = t.detail_min; lambda <= t.detail_max * 1.0001; lambda *= 1.6) {
    const double a = std::sqrt(lambda / t.detail_max);
    fine += a * periodic_noise(rng, size, static_cast<int>(std::lround(tile / lambda)));
    total += a;
  }
  fine /= std::max(total, 1e-9);
  cv::Mat out(size, size, CV_8UC3);
  const cv::Vec3f soil(0.52f, 0.42f, 0.30f), grass(0.30f, 0.42f, 0.20f);
  for (int r = 0; r < size; ++r) {
    for (int c = 0; c < size; ++c) {
      const float w = 1.f / (1.f + std::exp(-2.5f * patches.at<float>(r, c)));
      const float b = 1.f + 0.35f * fine.at<float>(r, c);
      const cv::Vec3f col = (w * soil + (1 - w) * grass) * b;
      for (int k = 0; k < 3; ++k)
        out.at<cv::Vec3b>(r, c)[k] = cv::saturate_cast<uchar>(255.f * col[k]);
    }
  }
  return out;
}

// Cloud density over a period of 8 cloud scales: periodic noise at 8, 16 and 32 cells a period (clouds
// of about `scale` metres, with ragged edges), thresholded at the quantile that covers `cover` of
// the sky with an edge `softness` wide in that quantile.
cv::Mat cloud_field(const sim::CloudSpec& c, std::uint64_t seed) {
  auto rng = sim::make_stream(seed, "clouds");
  const int size = 512;
  cv::Mat n = periodic_noise(rng, size, 8) + 0.5 * periodic_noise(rng, size, 16) + 0.25 * periodic_noise(rng, size, 32);
  std::vector<float> sorted(n.begin<float>(), n.end<float>());
  std::sort(sorted.begin(), sorted.end());
  auto quantile = [&](double q) {
    return sorted[static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * (sorted.size() - 1))];
  };
  const float lo = quantile(1 - c.cover - c.softness / 2), hi = quantile(1 - c.cover + c.softness / 2);
  cv::Mat out(size, size, CV_8U);
  for (int r = 0; r < size; ++r)
    for (int col = 0; col < size; ++col) {
      const float x = std::clamp((n.at<float>(r, col) - lo) / std::max(hi - lo, 1e-6f), 0.f, 1.f);
      out.at<std::uint8_t>(r, col) = cv::saturate_cast<std::uint8_t>(255 * x * x * (3 - 2 * x));
    }
  return out;
}

// Grey detail for the objects' surfaces (tinted by vertex colour).
cv::Mat detail_texture(std::uint64_t seed) {
  auto rng = sim::make_stream(seed, "object_texture");
  cv::Mat n = 0.5 * periodic_noise(rng, 256, 64) + 0.5 * periodic_noise(rng, 256, 16);
  cv::Mat out;
  n.convertTo(out, CV_8U, 40, 200);
  cv::Mat rgb;
  cv::cvtColor(out, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}

Mesh terrain_mesh(const sim::WorldSpec& world, const sim::TerrainModel& terrain, int material,
                  double tex_w, double tex_h) {
  const auto& spec = world.terrain;
  const Eigen::Vector4d& b = terrain.bounds();
  const int nx = static_cast<int>(std::lround((b(2) - b(0)) / spec.resolution)) + 1;
  const int ny = static_cast<int>(std::lround((b(3) - b(1)) / spec.resolution)) + 1;
  std::vector<double> h(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      h[j * nx + i] = terrain.height(b(0) + i * spec.resolution, b(1) + j * spec.resolution);
  const bool stretched = world.texture.mode == sim::TextureSpec::Mode::Stretched &&
                         world.texture.type == sim::TextureSpec::Type::Image;
  const bool image = world.texture.type == sim::TextureSpec::Type::Image;
  const double ox = image ? world.texture.origin_x : 0, oy = image ? world.texture.origin_y : 0;
  Mesh m;
  m.material = material;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = b(0) + i * spec.resolution, y = b(1) + j * spec.resolution;
      const double hx = (h[j * nx + std::min(i + 1, nx - 1)] - h[j * nx + std::max(i - 1, 0)]) /
                        ((std::min(i + 1, nx - 1) - std::max(i - 1, 0)) * spec.resolution);
      const double hy = (h[std::min(j + 1, ny - 1) * nx + i] - h[std::max(j - 1, 0) * nx + i]) /
                        ((std::min(j + 1, ny - 1) - std::max(j - 1, 0)) * spec.resolution);
      // Image up is world +y (north); t runs down the image rows.
      Eigen::Vector2d uv = stretched
                               ? Eigen::Vector2d((x - b(0)) / (b(2) - b(0)), (b(3) - y) / (b(3) - b(1)))
                               : Eigen::Vector2d((x - ox) / tex_w, (oy - y) / tex_h);
      m.add({x, y, h[j * nx + i]}, Eigen::Vector3d(-hx, -hy, 1).normalized(), uv, {1, 1, 1});
    }
  }
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const std::uint32_t a = j * nx + i, c = a + 1, d = a + nx, e = d + 1;
      m.indices.insert(m.indices.end(), {a, c, e, a, e, d});
    }
  }
  return m;
}

// Flat-shaded triangle, for the faceted objects.
void tri(Mesh& m, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
         const Eigen::Vector3d& colour, double uv_scale = 1.0) {
  Eigen::Vector3d n = (b - a).cross(c - a);
  if (n.norm() < 1e-12) return;
  n.normalize();
  // Project on the plane most facing the normal for texture coordinates.
  int ax = 0;
  n.cwiseAbs().maxCoeff(&ax);
  auto uv = [&](const Eigen::Vector3d& p) {
    const int i = (ax + 1) % 3, k = (ax + 2) % 3;
    return Eigen::Vector2d(p[i] / uv_scale, p[k] / uv_scale);
  };
  const auto base = static_cast<std::uint32_t>(m.vertex_count());
  m.add(a, n, uv(a), colour);
  m.add(b, n, uv(b), colour);
  m.add(c, n, uv(c), colour);
  m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
}

void quad(Mesh& m, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
          const Eigen::Vector3d& d, const Eigen::Vector3d& colour) {
  tri(m, a, b, c, colour);
  tri(m, a, c, d, colour);
}

Eigen::Matrix3d rz(double a) {
  Eigen::Matrix3d R;
  R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return R;
}

void add_box(Mesh& m, const Eigen::Vector3d& centre_base, const Eigen::Vector3d& size, double yaw,
             const Eigen::Vector3d& colour, double bottom = 0) {
  const Eigen::Matrix3d R = rz(yaw);
  auto P = [&](double sx, double sy, double z) {
    return Eigen::Vector3d(centre_base + R * Eigen::Vector3d(sx * size.x() / 2, sy * size.y() / 2, z));
  };
  const double z0 = bottom, z1 = size.z();
  const Eigen::Vector3d roof = colour * 0.8;
  quad(m, P(-1, -1, z1), P(1, -1, z1), P(1, 1, z1), P(-1, 1, z1), roof);
  quad(m, P(-1, -1, z0), P(1, -1, z0), P(1, -1, z1), P(-1, -1, z1), colour);
  quad(m, P(1, -1, z0), P(1, 1, z0), P(1, 1, z1), P(1, -1, z1), colour);
  quad(m, P(1, 1, z0), P(-1, 1, z0), P(-1, 1, z1), P(1, 1, z1), colour);
  quad(m, P(-1, 1, z0), P(-1, -1, z0), P(-1, -1, z1), P(-1, 1, z1), colour);
}

void add_cone(Mesh& m, const Eigen::Vector3d& base, double radius, double z0, double z1,
              double top_radius, const Eigen::Vector3d& colour, int segments = 10) {
  for (int s = 0; s < segments; ++s) {
    const double a0 = 2 * M_PI * s / segments, a1 = 2 * M_PI * (s + 1) / segments;
    const Eigen::Vector3d b0 = base + Eigen::Vector3d(radius * std::cos(a0), radius * std::sin(a0), z0);
    const Eigen::Vector3d b1 = base + Eigen::Vector3d(radius * std::cos(a1), radius * std::sin(a1), z0);
    const Eigen::Vector3d t0 = base + Eigen::Vector3d(top_radius * std::cos(a0), top_radius * std::sin(a0), z1);
    const Eigen::Vector3d t1 = base + Eigen::Vector3d(top_radius * std::cos(a1), top_radius * std::sin(a1), z1);
    if (top_radius > 0)
      quad(m, b0, b1, t1, t0, colour);
    else
      tri(m, b0, b1, t0, colour);
  }
}

// A lumpy rock: an octahedron subdivided twice onto a sphere, radii perturbed by its seed.
void add_boulder(Mesh& m, const sim::WorldObject& o) {
  std::vector<Eigen::Vector3d> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<std::array<int, 3>> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int level = 0; level < 2; ++level) {
    std::vector<std::array<int, 3>> nf;
    for (auto [a, b, c] : f) {
      const int ab = static_cast<int>(v.size());
      v.push_back((v[a] + v[b]).normalized());
      v.push_back((v[b] + v[c]).normalized());
      v.push_back((v[c] + v[a]).normalized());
      nf.push_back({a, ab, ab + 2});
      nf.push_back({ab, b, ab + 1});
      nf.push_back({ab + 2, ab + 1, c});
      nf.push_back({ab, ab + 1, ab + 2});
    }
    f = nf;
  }
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u(0.75, 1.2);
  // Same direction, same radius: vertices duplicated by the subdivision stay together.
  std::vector<double> r(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    r[i] = u(rng);
    for (std::size_t j = 0; j < i; ++j)
      if ((v[j] - v[i]).norm() < 1e-9) r[i] = r[j];
  }
  const Eigen::Matrix3d R = rz(o.yaw);
  const Eigen::Vector3d half(o.size.x() / 2, o.size.y() / 2, o.size.z());
  auto P = [&](int i) {
    Eigen::Vector3d p = v[i] * r[i];
    p.z() = p.z() * 0.8 + 0.2;  // sunk a little into the ground
    return Eigen::Vector3d(o.position + R * p.cwiseProduct(half));
  };
  for (auto [a, b, c] : f) tri(m, P(a), P(b), P(c), o.colour, 0.7);
}

Mesh objects_mesh(const std::vector<sim::WorldObject>& objects, int material) {
  Mesh m;
  m.material = material;
  for (const auto& o : objects) {
    switch (o.type) {
      case sim::WorldObject::Type::Boulder:
        add_boulder(m, o);
        break;
      case sim::WorldObject::Type::Tree: {
        const double h = o.size.z(), r = o.size.x() / 2;
        add_cone(m, o.position, 0.15 * r, -0.3, 0.4 * h, 0.1 * r, {0.35, 0.25, 0.15}, 6);
        add_cone(m, o.position, r, 0.3 * h, 0.75 * h, 0.0, o.colour);
        add_cone(m, o.position, 0.75 * r, 0.55 * h, h, 0.0, o.colour * 1.1);
        break;
      }
      case sim::WorldObject::Type::Building: {
        add_box(m, o.position, o.size, o.yaw, o.colour, -0.5);
        // A roof ridge of half the building's height above a third of its width.
        const Eigen::Matrix3d R = rz(o.yaw);
        const Eigen::Vector3d sz(o.size.x() * 0.9, o.size.y() * 0.3, 0.8);
        add_box(m, o.position + R * Eigen::Vector3d(0, 0, o.size.z()), sz, o.yaw,
                {0.55, 0.2, 0.15});
        break;
      }
    }
  }
  return m;
}

Eigen::Vector3d to_vec(const aiVector3D& v) { return {v.x, v.y, v.z}; }

// Solids (objects, the lead's model) are sampled without anisotropic filtering. Their faces can be
// seen edge-on, where the texture footprint of a pixel is unbounded, and llvmpipe filters
// anisotropically by an elliptical weighted average over every texel of the footprint's bounding
// box at the chosen mipmap level (gallivm's lp_build_sample_aniso): once the footprint outgrows
// the coarsest level that box is no longer bounded, and with MSAA shading such slivers a single
// frame took minutes (docs/studies/render-object-cost.md). A solid's faces are small and seen
// from above; the ground and the flat cue keep world.texture.anisotropy.
constexpr double kSolidAnisotropy = 1.0;

constexpr double kCueLift = sim::kLeadCueLift;

// A model's materials: its colours, and for each one that carries a texture a Material appended to
// scene.materials (its index, -1 for none). `what` names the model in errors.
std::vector<int> load_materials(const aiScene* ai, const fs::path& dir, const std::string& kind, const std::string& what,
                                const Material& sampling, std::vector<Eigen::Vector3d>& mat_colour, Scene& scene) {
  std::vector<int> mat_index(ai->mNumMaterials, -1);
  mat_colour.assign(ai->mNumMaterials, Eigen::Vector3d::Ones());
  std::error_code ec;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
    const aiMaterial* m = ai->mMaterials[i];
    aiColor4D c;
    if (m->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || m->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
      mat_colour[i] = {c.r, c.g, c.b};
    aiString tex;
    if (m->GetTexture(aiTextureType_DIFFUSE, 0, &tex) != AI_SUCCESS &&
        m->GetTexture(aiTextureType_BASE_COLOR, 0, &tex) != AI_SUCCESS)
      continue;
    Material mat;
    mat.anisotropy = kSolidAnisotropy;
    mat.trilinear = sampling.trilinear;
    if (const aiTexture* emb = ai->GetEmbeddedTexture(tex.C_Str())) {
      cv::Mat raw;
      if (emb->mHeight == 0) {
        cv::Mat buf(1, static_cast<int>(emb->mWidth), CV_8U, emb->pcData);
        raw = cv::imdecode(buf, cv::IMREAD_COLOR);
      }
      if (raw.empty())
        throw std::runtime_error(what + ": cannot decode embedded texture '" + tex.C_Str() + "'");
      cv::cvtColor(raw, mat.texture, cv::COLOR_BGR2RGB);
    } else {
      std::string name = tex.C_Str();
      std::replace(name.begin(), name.end(), '\\', '/');
      const fs::path tp = dir / name;
      if (!fs::is_regular_file(tp, ec)) throw std::runtime_error(what + ": texture '" + tp.string() + "' not found");
      mat.texture = read_image_rgb(tp.string(), (kind + " texture").c_str());
    }
    mat_index[i] = static_cast<int>(scene.materials.size());
    scene.materials.push_back(std::move(mat));
  }
  return mat_index;
}

}  // namespace

std::vector<Mesh> load_model(const ModelPlacement& place, const std::string& path, const Material& sampling,
                             Scene& scene) {
  const std::string what = place.what + " '" + path + "'";
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw std::runtime_error(what + ": file not found");
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                aiProcess_JoinIdenticalVertices);
  if (!ai || !ai->mRootNode || ai->mNumMeshes == 0)
    throw std::runtime_error(what + ": not a 3D model assimp can read (" +
                             (ai ? std::string("no meshes") : std::string(importer.GetErrorString())) +
                             ")");
  // Up axis to z: glTF's y-up becomes z-up by a +90 deg rotation about x.
  Eigen::Matrix3d U = Eigen::Matrix3d::Identity();
  if (place.up == "y") U << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (unsigned i = 0; i < ai->mNumMeshes; ++i)
    for (unsigned k = 0; k < ai->mMeshes[i]->mNumVertices; ++k) {
      const Eigen::Vector3d p = U * to_vec(ai->mMeshes[i]->mVertices[k]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  const double extent = hi.z() - lo.z();
  if (!(extent > 0)) throw std::runtime_error(what + ": has no height");
  const double s = place.height / extent;
  const Eigen::Vector3d ref(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), place.on_top ? hi.z() : lo.z());

  std::vector<Eigen::Vector3d> mat_colour;
  const std::vector<int> mat_index = load_materials(ai, fs::path(path).parent_path(), place.what, what, sampling,
                                                    mat_colour, scene);
  std::vector<Mesh> out;
  for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
    const aiMesh* am = ai->mMeshes[i];
    Mesh m;
    m.material = mat_index[am->mMaterialIndex];
    const Eigen::Vector3d colour = mat_colour[am->mMaterialIndex];
    for (unsigned k = 0; k < am->mNumVertices; ++k) {
      const Eigen::Vector3d p = s * (U * to_vec(am->mVertices[k]) - ref) + place.offset;
      const Eigen::Vector3d n = am->HasNormals() ? Eigen::Vector3d(U * to_vec(am->mNormals[k])) : Eigen::Vector3d(0, 0, 1);
      const Eigen::Vector2d uv = am->HasTextureCoords(0)
                                     ? Eigen::Vector2d(am->mTextureCoords[0][k].x, 1.0 - am->mTextureCoords[0][k].y)
                                     : Eigen::Vector2d(0, 0);
      m.add(p, n, uv, colour);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      if (am->mFaces[f].mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) m.indices.push_back(am->mFaces[f].mIndices[k]);
    }
    out.push_back(std::move(m));
  }
  return out;
}

void load_lead_model(const sim::LeadModelSpec& spec, const std::string& path, const Material& sampling,
                     Scene& scene) {
  // The reference point on the roof, the cue kCueLift above it.
  const ModelPlacement place{"lead model", spec.up, spec.height, true, Eigen::Vector3d(0, 0, -kCueLift)};
  for (Mesh& m : load_model(place, path, sampling, scene)) scene.lead_meshes.push_back(std::move(m));

  // The cue: a flat square centred on the reference point, kCueLift above the roof.
  if (spec.cue == sim::LeadModelSpec::Cue::None) return;
  Material cue;
  cue.anisotropy = sampling.anisotropy;
  cue.trilinear = sampling.trilinear;
  cue.repeat = false;
  cue.unlit = true;
  double side = spec.marker_size;
  if (spec.cue == sim::LeadModelSpec::Cue::Aruco) {
    // DICT_4X4_50: 4x4 bits plus a one-cell black border = 6 cells; a white one-cell quiet zone.
    const int cell = 32;
    cv::Mat marker;
    cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50), spec.aruco_id,
                          6 * cell, marker, 1);
    cv::Mat framed;
    cv::copyMakeBorder(marker, framed, cell, cell, cell, cell, cv::BORDER_CONSTANT, cv::Scalar(255));
    cv::cvtColor(framed, cue.texture, cv::COLOR_GRAY2RGB);
    side = spec.marker_size * 8.0 / 6.0;
  } else {
    cue.texture = cv::Mat(4, 4, CV_8UC3,
                          cv::Scalar(255 * spec.panel_colour.x(), 255 * spec.panel_colour.y(),
                                     255 * spec.panel_colour.z()));
  }
  cue.mipmaps = true;
  scene.materials.push_back(cue);
  Mesh q;
  q.material = static_cast<int>(scene.materials.size()) - 1;
  const double h = side / 2, z = 0.0;
  // Texture row 0 (the marker's top) towards the lead's front (+x), its left to +y.
  q.add({h, h, z}, {0, 0, 1}, {0, 0}, {1, 1, 1});
  q.add({h, -h, z}, {0, 0, 1}, {1, 0}, {1, 1, 1});
  q.add({-h, -h, z}, {0, 0, 1}, {1, 1}, {1, 1, 1});
  q.add({-h, h, z}, {0, 0, 1}, {0, 1}, {1, 1, 1});
  q.indices = {0, 1, 2, 0, 2, 3};
  scene.lead_meshes.push_back(std::move(q));
}

namespace {

void stochastic_tiling(const sim::TextureSpec& t, std::uint64_t seed, Material& m) {
  if (t.tiling != sim::TextureSpec::Tiling::Stochastic) return;
  m.stochastic_cell = t.cell;
  m.blend_sharpness = t.blend_sharpness;
  m.bake = t.bake;
  auto rng = sim::make_stream(seed, "ground_tiling");
  m.stochastic_seed = static_cast<std::uint32_t>(rng());
}

}  // namespace

Scene build_scene(const sim::WorldDescription& world) {
  const sim::WorldSpec& w = world.spec;
  Scene scene;
  scene.light = w.light;
  if (w.light.sun.enabled) scene.light.direction = w.light.travel();
  if (w.light.clouds.cover > 0) scene.clouds = cloud_field(w.light.clouds, world.seed);
  scene.sky = w.image.sky;
  scene.near = w.near;
  scene.far = w.far;
  scene.msaa = w.image.msaa;

  Material ground;
  ground.anisotropy = w.texture.anisotropy;
  ground.trilinear = w.texture.filter == sim::TextureSpec::Filter::Trilinear;
  double tex_w = w.texture.tile_size, tex_h = w.texture.tile_size;
  if (w.texture.type == sim::TextureSpec::Type::Image) {
    const std::string p = sim::resolve_asset(w.texture.image, world.scenario_path, "ground texture");
    ground.texture = read_image_rgb(p, "ground texture");
    ground.repeat = w.texture.mode == sim::TextureSpec::Mode::Tiled;
    if (ground.repeat) stochastic_tiling(w.texture, world.seed, ground);
    // Keep the image's aspect ratio: tile_size is its width.
    tex_h = tex_w * ground.texture.rows / ground.texture.cols;
  } else {
    ground.texture = procedural_ground(w.texture, world.seed);
    tex_w = tex_h = w.texture.size * w.texture.detail_min;
    stochastic_tiling(w.texture, world.seed, ground);
  }
  scene.materials.push_back(ground);
  scene.static_meshes.push_back(terrain_mesh(w, world.terrain, 0, tex_w, tex_h));

  const auto& objects = world.objects;
  if (!objects.empty()) {
    Material detail;
    detail.texture = detail_texture(world.seed);
    detail.anisotropy = kSolidAnisotropy;
    detail.trilinear = ground.trilinear;
    scene.materials.push_back(detail);
    scene.static_meshes.push_back(
        objects_mesh(objects, static_cast<int>(scene.materials.size()) - 1));
  }
  load_lead_model(w.lead, sim::resolve_asset(w.lead.model, world.scenario_path, "lead model"), ground, scene);
  if (w.uav_bodies.enabled) {
    const sim::UavBodiesSpec& b = w.uav_bodies;
    const ModelPlacement place{"UAV body model", b.up, b.height, false, Eigen::Vector3d::Zero()};
    scene.body_meshes = load_model(place, sim::resolve_asset(b.model, world.scenario_path, "UAV body model"), ground, scene);
  }
  return scene;
}

}  // namespace wingman::render
