#include "render/renderer.hpp"

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "render/gl_functions.hpp"
#include "render/ground_bake.hpp"
#include "render/piece_table.hpp"
#include "render/shaders.hpp"
#include "render/skylight.hpp"

namespace wingman::render {

using namespace shaders;

namespace {

// A run of triangles of one mesh (a range of its index buffer) and their bounding box.
struct Chunk {
  Eigen::AlignedBox3f box;
  GLsizei count = 0;
  std::size_t first = 0;  // index of its first index
};

struct GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  int material = -1;
  std::vector<Chunk> chunks;
};

// Static meshes are cut into square cells of this many metres (by triangle centroid, world x/y)
// so that a frame draws only the cells in view: the terrain and the objects cover the whole
// flight plus its margin, a camera sees about a tenth of that, and llvmpipe transforms, clips and
// bins every vertex it is given on the application's thread, before rasterising starts.
constexpr double kChunkSize = 16;

// The mesh's triangle indices reordered cell by cell, and the cells.
std::vector<Chunk> chunk_triangles(const Mesh& m, double cell, std::vector<std::uint32_t>& out) {
  std::map<std::pair<long, long>, std::vector<std::uint32_t>> cells;
  for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3) {
    Eigen::Vector3f c = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) c += Eigen::Map<const Eigen::Vector3f>(&m.positions[3 * m.indices[i + k]]);
    c /= 3;
    auto& tris = cells[{std::lround(std::floor(c.x() / cell)), std::lround(std::floor(c.y() / cell))}];
    tris.insert(tris.end(), m.indices.begin() + i, m.indices.begin() + i + 3);
  }
  std::vector<Chunk> chunks;
  out.clear();
  for (const auto& [key, tris] : cells) {
    Chunk ch;
    ch.first = out.size();
    ch.count = static_cast<GLsizei>(tris.size());
    for (auto v : tris) ch.box.extend(Eigen::Map<const Eigen::Vector3f>(&m.positions[3 * v]));
    out.insert(out.end(), tris.begin(), tris.end());
    chunks.push_back(ch);
  }
  return chunks;
}

// Whether any of the box can be in front of the camera and inside the image (clip = PV x):
// false only when all eight corners are beyond one side of the view frustum.
// Clip space to one in which window rectangle r of a w x h viewport, grown by a pixel, spans the
// clip cube's x and y: a box in_view() finds outside it draws no pixel of r.
Eigen::Matrix4f region_from_clip(const cv::Rect& r, int w, int h) {
  const float x0 = 2.f * static_cast<float>(r.x - 1) / static_cast<float>(w) - 1.f;
  const float x1 = 2.f * static_cast<float>(r.x + r.width + 1) / static_cast<float>(w) - 1.f;
  const float y0 = 2.f * static_cast<float>(r.y - 1) / static_cast<float>(h) - 1.f;
  const float y1 = 2.f * static_cast<float>(r.y + r.height + 1) / static_cast<float>(h) - 1.f;
  Eigen::Matrix4f T = Eigen::Matrix4f::Identity();
  T(0, 0) = 2.f / (x1 - x0), T(0, 3) = -(x0 + x1) / (x1 - x0);
  T(1, 1) = 2.f / (y1 - y0), T(1, 3) = -(y0 + y1) / (y1 - y0);
  return T;
}

bool in_view(const Eigen::AlignedBox3f& box, const Eigen::Matrix4f& clip_from_world) {
  int outside[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3f p = box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(i));
    const Eigen::Vector4f c = clip_from_world * p.homogeneous();
    const float w = 1.001f * c.w();  // a little slack against rounding at the image border
    outside[0] += c.x() < -w;
    outside[1] += c.x() > w;
    outside[2] += c.y() < -w;
    outside[3] += c.y() > w;
    outside[4] += c.w() <= 0;  // behind the camera (clip w = camera z)
  }
  for (int n : outside)
    if (n == 8) return false;
  return true;
}

struct GpuMaterial {
  GLuint tex = 0;
  bool unlit = false;
  // Stochastic tiling (kStochasticLookup); cell 0: the texture as it is.
  float cell = 0, aspect = 1, sharpness = 1;
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  GLuint pieces = 0;  // the piece table's texture
};

// The uniform locations of kRollingEye; -1 in a program without it.
struct RollingUniforms {
  GLint knots = -1, group = -1, row_of = -1, dist = -1, k3 = -1;
};

// The uniform locations of one colour program; -1 for those it lacks (glUniform ignores them).
struct ColourProgram {
  GLuint id = 0;
  RollingUniforms roll;
  GLint model_view = -1, proj = -1, model_rot = -1, tex = -1, to_light = -1, ambient = -1, bounce = -1,
        diffuse = -1, unlit = -1;
  GLint light_from_model = -1, shadow = -1, zero_to_one = -1, model = -1, cloud_tex = -1, cloud_offset = -1,
        cloud_period = -1, cloud_height = -1, cloud_block = -1;
  GLint cell = -1, aspect = -1, sharpness = -1, mean = -1, pieces = -1;
};

struct DepthProgram {
  GLuint id = 0;
  GLint model_view = -1, proj = -1;
  RollingUniforms roll;
};

// A rolling shutter's frame being drawn in one pass (CameraView::rows): the knots' model-views
// per group of meshes (0 the static scene, 1 the lead, 2 + i body i), on the GPU as kRollingEye's
// u_knots.
struct RollingFrame {
  bool on = false;
  GLuint tex = 0;
  std::vector<std::vector<Eigen::Matrix4d>> model_view;  // [group][knot]
  Eigen::Vector4f row_of = Eigen::Vector4f::Zero(), dist = Eigen::Vector4f::Zero();
  float k3 = 0;
};

struct Target {
  int w = 0, h = 0, samples = 1;
  GLuint ms_fbo = 0, ms_colour = 0, ms_depth = 0;  // MSAA: renderbuffers, colour blitted to fbo
  GLuint fbo = 0, colour = 0, depth = 0;           // what is read back
  cv::Mat rgba;  // readback buffer, reused
};

// Window depth d = alpha + beta / z of the camera-frame depth z, exactly as the rasteriser
// interpolates it (1/z is affine in screen space); read back, z = beta / (d - alpha). Reversed-Z
// (near at 1, far at 0, with glClipControl's [0, 1] depth range) keeps float's relative precision
// at every distance (worst 6 um at 20 m on llvmpipe); without clip control the classic mapping
// (d crowding towards 1) is used: 2.7 mm at 20 m, 0.2 m at 400 m. `clear`: where nothing was drawn.
struct DepthMap {
  bool reversed = false;
  double alpha = 0, beta = 0;
  float clear = 1;
};

DepthMap depth_map(double n, double f, bool reversed) {
  if (reversed) return {true, -n / (f - n), n * f / (f - n), 0.f};
  return {false, f / (f - n), -n * f / (f - n), 1.f};
}

// Window depth to metres along the optical axis, in place; 0 where nothing was drawn. Float and
// branch-free so that it vectorises: in double it took 1.3 ms a megapixel, on the thread that
// waits for the frame. d - alpha is formed as (d - clear) - (alpha - clear): exact for d near
// the clear value, where the classic mapping's alpha (1.0001) rounded to float would cost mm.
void to_metric_depth(cv::Mat& d, const DepthMap& m) {
  const float clear = m.clear, rest = static_cast<float>(m.alpha - m.clear),
              beta = static_cast<float>(m.beta);
  for (int r = 0; r < d.rows; ++r) {
    float* p = d.ptr<float>(r);
    for (int c = 0; c < d.cols; ++c) {
      const float z = beta / ((p[c] - clear) - rest);  // never 0 / 0: alpha lies outside [0, 1]
      p[c] = p[c] != clear ? z : 0.f;  // a select, not a branch around the division
    }
  }
}

Eigen::Matrix4f to_float(const Eigen::Matrix4d& m) { return m.cast<float>(); }

}  // namespace

cv::Mat Frame::gray() const {
  cv::Mat g;
  cv::cvtColor(rgb, g, cv::COLOR_RGB2GRAY);
  return g;
}

struct Renderer::Impl {
  GlFunctions gl;
  GLuint white = 0;
  // The depth-only program, with one view or a rolling shutter's (made at its first frame).
  DepthProgram depth_program[2];
  // The colour programs by [rolling][shadowed][stochastic]; id 0 where the scene needs none (the
  // rolling ones are made at the first frame drawn in one pass).
  ColourProgram colour[2][2][2];
  bool stochastic = false;  // whether any material is stochastically tiled
  RollingFrame roll;
  int group = 0;  // the meshes being drawn (RollingFrame's groups)
  SkyLight sky;
  // The shadow map and the cloud texture, when the world has shadows.
  struct Shadowed {
    GLuint fbo = 0, map = 0, clouds = 0;
    double time = 0;  // s of the frame being drawn
    // The map drawn last: its clip space and its casters; and how many were drawn.
    bool kept = false;
    Eigen::Matrix4d L = Eigen::Matrix4d::Identity();
    std::optional<Eigen::Matrix4d> lead;
    std::vector<Eigen::Matrix4d> bodies;
    int drawn = 0;
  } sh;
  std::vector<GpuMaterial> materials;
  std::vector<GpuMesh> static_meshes, lead_meshes, body_meshes;
  std::vector<Eigen::Matrix4d> body_models;  // this render's UAV bodies (CameraView::bodies)
  std::map<std::pair<int, int>, Target> targets;
  // Clip space to the clip space of the region being drawn: chunks wholly outside it are skipped
  // (identity: the whole image).
  Eigen::Matrix4f cull = Eigen::Matrix4f::Identity();
  std::vector<GLsizei> draw_counts;  // per-frame draw ranges, kept to avoid reallocating
  std::vector<const void*> draw_offsets;
  Scene info;  // light, sky, near, far, msaa (meshes cleared)
  float max_aniso = 1;
  DepthMap depth;  // reversed-Z where the context has glClipControl

  // Every source is the version line and the parts given, in order.
  GLuint compile(GLenum type, std::initializer_list<const char*> parts) {
    std::vector<const char*> src{"#version 330 core\n"};
    src.insert(src.end(), parts.begin(), parts.end());
    GLuint s = gl.CreateShader(type);
    gl.ShaderSource(s, static_cast<GLsizei>(src.size()), src.data(), nullptr);
    gl.CompileShader(s);
    GLint ok = 0;
    gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[4096];
      gl.GetShaderInfoLog(s, sizeof log, nullptr, log);
      throw std::runtime_error(std::string("renderer: shader compile failed: ") + log);
    }
    return s;
  }
  GLuint link(std::initializer_list<const char*> vs, std::initializer_list<const char*> fs) {
    GLuint p = gl.CreateProgram();
    GLuint a = compile(GL_VERTEX_SHADER, vs), b = compile(GL_FRAGMENT_SHADER, fs);
    gl.AttachShader(p, a);
    gl.AttachShader(p, b);
    gl.LinkProgram(p);
    gl.DeleteShader(a);
    gl.DeleteShader(b);
    GLint ok = 0;
    gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[4096];
      gl.GetProgramInfoLog(p, sizeof log, nullptr, log);
      throw std::runtime_error(std::string("renderer: shader link failed: ") + log);
    }
    return p;
  }

  GLuint upload_texture(const cv::Mat& img, bool repeat, bool mipmaps, bool trilinear,
                        double anisotropy) {
    cv::Mat rgba;
    if (img.channels() == 3)
      cv::cvtColor(img, rgba, cv::COLOR_RGB2RGBA);
    else if (img.channels() == 4)
      rgba = img;
    else
      cv::cvtColor(img, rgba, cv::COLOR_GRAY2RGBA);
    if (!rgba.isContinuous()) rgba = rgba.clone();
    GLuint t = 0;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgba.cols, rgba.rows, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                  rgba.data);
    set_sampling(repeat, mipmaps, trilinear, anisotropy);
    return t;
  }

  // The bound texture's wrapping and filtering (its mipmaps made when it has them).
  void set_sampling(bool repeat, bool mipmaps, bool trilinear, double anisotropy) {
    const GLint wrap = repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    if (mipmaps) {
      gl.GenerateMipmap(GL_TEXTURE_2D);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                       trilinear ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR_MIPMAP_NEAREST);
      if (max_aniso > 1 && anisotropy > 1)
        gl.TexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY,
                         std::min<float>(max_aniso, static_cast<float>(anisotropy)));
    } else {
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    }
  }

  GpuMaterial upload_material(const Material& m) {
    GpuMaterial g;
    g.tex = m.texture.empty() ? 0 : upload_texture(m.texture, m.repeat, m.mipmaps, m.trilinear, m.anisotropy);
    g.unlit = m.unlit;
    if (m.stochastic_cell > 0 && !m.texture.empty()) {
      g.aspect = static_cast<float>(m.texture.rows) / static_cast<float>(m.texture.cols);
      g.cell = static_cast<float>(m.stochastic_cell * std::min(1.0f, g.aspect));
      g.sharpness = static_cast<float>(m.blend_sharpness);
      const cv::Scalar mean = cv::mean(m.texture);
      g.mean = Eigen::Vector3f(mean[0], mean[1], mean[2]) / 255.f;
      const double aspect = static_cast<double>(m.texture.rows) / m.texture.cols;
      g.pieces = upload_pieces(piece_table(m.stochastic_cell * std::min(1.0, aspect), aspect, m.stochastic_seed));
    }
    return g;
  }

  // The piece table as an RG32F texture read with texelFetch (no filtering, no mipmaps).
  GLuint upload_pieces(const PieceTable& t) {
    GLuint x = 0;
    gl.GenTextures(1, &x);
    gl.BindTexture(GL_TEXTURE_2D, x);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, PieceTable::kSize, PieceTable::kSize, 0, GL_RG, GL_FLOAT,
                  t.centres.data());
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return x;
  }

  // cell: chunk size in metres; 0 for one chunk (the lead, which moves). bake: the baked ground
  // the mesh's texture coordinates map into, if its material is one.
  GpuMesh upload_mesh(const Mesh& m, double cell, const GroundBake* bake = nullptr) {
    GpuMesh g;
    g.material = m.material;
    std::vector<std::uint32_t> indices;
    if (cell > 0) {
      g.chunks = chunk_triangles(m, cell, indices);
    } else {
      indices = m.indices;
      Chunk all;
      all.count = static_cast<GLsizei>(indices.size());
      for (auto v : indices) all.box.extend(Eigen::Map<const Eigen::Vector3f>(&m.positions[3 * v]));
      g.chunks.push_back(all);
    }
    const std::size_t n = m.vertex_count();
    std::vector<float> v;
    v.reserve(n * 11);
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) v.push_back(m.positions[3 * i + k]);
      for (int k = 0; k < 3; ++k) v.push_back(m.normals[3 * i + k]);
      const Eigen::Vector2d uv(m.uvs[2 * i], m.uvs[2 * i + 1]);
      const Eigen::Vector2f st = (bake ? bake->map(uv) : uv).cast<float>();
      v.push_back(st.x());
      v.push_back(st.y());
      for (int k = 0; k < 3; ++k) v.push_back(m.colours[3 * i + k]);
    }
    gl.GenVertexArrays(1, &g.vao);
    gl.BindVertexArray(g.vao);
    gl.GenBuffers(1, &g.vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, g.vbo);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(float)), v.data(),
                  GL_STATIC_DRAW);
    gl.GenBuffers(1, &g.ebo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ebo);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER,
                  static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)), indices.data(),
                  GL_STATIC_DRAW);
    const GLsizei stride = 11 * sizeof(float);
    const int sizes[4] = {3, 3, 2, 3};
    std::size_t off = 0;
    for (GLuint a = 0; a < 4; ++a) {
      gl.EnableVertexAttribArray(a);
      gl.VertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, stride,
                             reinterpret_cast<const void*>(off * sizeof(float)));
      off += sizes[a];
    }
    gl.BindVertexArray(0);
    return g;
  }

  // The mesh's chunks in view of any of the clip spaces, adjacent ones merged, in one call.
  void draw_visible(const GpuMesh& m, const std::vector<Eigen::Matrix4f>& clips_from_model) {
    draw_counts.clear();
    draw_offsets.clear();
    std::size_t end = 0;
    for (const Chunk& c : m.chunks) {
      if (std::none_of(clips_from_model.begin(), clips_from_model.end(),
                       [&](const Eigen::Matrix4f& clip) { return in_view(c.box, clip); }))
        continue;
      if (!draw_counts.empty() && c.first == end) {
        draw_counts.back() += c.count;
      } else {
        draw_counts.push_back(c.count);
        draw_offsets.push_back(reinterpret_cast<const void*>(c.first * sizeof(std::uint32_t)));
      }
      end = c.first + static_cast<std::size_t>(c.count);
    }
    if (draw_counts.empty()) return;
    gl.BindVertexArray(m.vao);
    gl.MultiDrawElements(GL_TRIANGLES, draw_counts.data(), GL_UNSIGNED_INT, draw_offsets.data(),
                         static_cast<GLsizei>(draw_counts.size()));
  }

  // The scene from view V: textured and lit (colour), or positions only (depth pass). light: the
  // sun's clip space from the world, for the shadowed colour programs; null for the plain ones.
  void draw_scene(bool colour, const Eigen::Matrix4f& P, const Eigen::Matrix4d& V,
                  const std::optional<Eigen::Matrix4d>& lead_model, const Eigen::Matrix4f* light = nullptr) {
    if (colour && light) {
      gl.ActiveTexture(GL_TEXTURE1);
      gl.BindTexture(GL_TEXTURE_2D, sh.map);
      gl.ActiveTexture(GL_TEXTURE2);
      gl.BindTexture(GL_TEXTURE_2D, sh.clouds ? sh.clouds : white);
      gl.ActiveTexture(GL_TEXTURE0);
    }
    const Pass pass{colour, P, V, light};
    draw_meshes(pass, static_meshes, Eigen::Matrix4d::Identity(), 0);
    if (lead_model) draw_meshes(pass, lead_meshes, *lead_model, 1);
    for (std::size_t i = 0; i < body_models.size(); ++i)
      draw_meshes(pass, body_meshes, body_models[i], 2 + static_cast<int>(i));
  }

  // The clip spaces from group g's model under a rolling shutter: its first, middle and last
  // knots (a chunk in view of none of them is off the image, the readout being short).
  std::vector<Eigen::Matrix4f> rolling_clips(const Eigen::Matrix4f& P, int g) const {
    const auto& mv = roll.model_view[static_cast<std::size_t>(g)];
    std::vector<Eigen::Matrix4f> clips;
    for (std::size_t k : {std::size_t{0}, mv.size() / 2, mv.size() - 1}) clips.push_back(P * to_float(mv[k]));
    return clips;
  }

  void set_rolling(const RollingUniforms& u) {
    if (!roll.on) return;
    gl.Uniform1i(u.knots, 4);
    gl.Uniform1i(u.group, group);
    gl.Uniform4fv(u.row_of, 1, roll.row_of.data());
    gl.Uniform4fv(u.dist, 1, roll.dist.data());
    gl.Uniform1f(u.k3, roll.k3);
  }

  struct Pass {
    bool colour;
    const Eigen::Matrix4f& P;
    const Eigen::Matrix4d& V;
    const Eigen::Matrix4f* light;
  };

  // Makes p current with the pass's and the model M's uniforms.
  void use(const ColourProgram& p, const Pass& pass, const Eigen::Matrix4d& M) {
    gl.UseProgram(p.id);
    const Eigen::Matrix4f MV = to_float(pass.V * M);
    const Eigen::Matrix3f R = M.topLeftCorner<3, 3>().cast<float>();
    gl.UniformMatrix4fv(p.proj, 1, GL_FALSE, pass.P.data());
    gl.UniformMatrix4fv(p.model_view, 1, GL_FALSE, MV.data());
    gl.UniformMatrix3fv(p.model_rot, 1, GL_FALSE, R.data());
    const Eigen::Vector3f to_light = (-info.light.direction.normalized()).cast<float>();
    const Eigen::Vector3f ambient = sky.sky.cast<float>(), bounce = sky.ground.cast<float>(),
                          diffuse = sky.beam.cast<float>();
    gl.Uniform3fv(p.to_light, 1, to_light.data());
    gl.Uniform3fv(p.ambient, 1, ambient.data());
    gl.Uniform3fv(p.bounce, 1, bounce.data());
    gl.Uniform3fv(p.diffuse, 1, diffuse.data());
    gl.Uniform1i(p.tex, 0);
    set_rolling(p.roll);
    if (!pass.light) return;
    const Eigen::Matrix4f L = *pass.light * to_float(M), Mf = to_float(M);
    gl.UniformMatrix4fv(p.light_from_model, 1, GL_FALSE, L.data());
    gl.UniformMatrix4fv(p.model, 1, GL_FALSE, Mf.data());
    gl.Uniform1i(p.shadow, 1);
    gl.Uniform1i(p.zero_to_one, depth.reversed ? 1 : 0);
    const sim::CloudSpec& c = info.light.clouds;
    const Eigen::Vector2f drift = (c.wind.head<2>() * sh.time).cast<float>();
    gl.Uniform1i(p.cloud_tex, 2);
    gl.Uniform2fv(p.cloud_offset, 1, drift.data());
    gl.Uniform1f(p.cloud_period, static_cast<float>(8 * c.scale));
    gl.Uniform1f(p.cloud_height, static_cast<float>(c.height));
    gl.Uniform1f(p.cloud_block, sh.clouds ? static_cast<float>(1 - c.transmission) : 0.f);
  }

  // Binds a mesh's material to the colour program that draws it (made current first when another
  // one is).
  void bind_material(const GpuMaterial* mat, const Pass& pass, const Eigen::Matrix4d& M,
                     const ColourProgram*& current) {
    const ColourProgram& p = colour[roll.on ? 1 : 0][pass.light ? 1 : 0][mat && mat->cell > 0 ? 1 : 0];
    if (&p != current) use(p, pass, M);
    current = &p;
    gl.BindTexture(GL_TEXTURE_2D, mat && mat->tex ? mat->tex : white);
    gl.Uniform1i(p.unlit, mat && mat->unlit ? 1 : 0);
    if (mat && mat->cell > 0) bind_stochastic(p, *mat);
  }

  // A stochastically tiled material's uniforms and piece table (kStochasticLookup) on p.
  void bind_stochastic(const ColourProgram& p, const GpuMaterial& mat) {
    gl.Uniform1f(p.cell, mat.cell);
    gl.Uniform1f(p.aspect, mat.aspect);
    gl.Uniform1f(p.sharpness, mat.sharpness);
    gl.Uniform3fv(p.mean, 1, mat.mean.data());
    gl.Uniform1i(p.pieces, 3);
    gl.ActiveTexture(GL_TEXTURE3);
    gl.BindTexture(GL_TEXTURE_2D, mat.pieces);
    gl.ActiveTexture(GL_TEXTURE0);
  }

  // Meshes of group g (RollingFrame) at model matrix M.
  void draw_meshes(const Pass& pass, const std::vector<GpuMesh>& meshes, const Eigen::Matrix4d& M, int g) {
    group = g;
    std::vector<Eigen::Matrix4f> clips =
        roll.on ? rolling_clips(pass.P, g) : std::vector<Eigen::Matrix4f>{pass.P * to_float(pass.V * M)};
    for (Eigen::Matrix4f& c : clips) c = cull * c;
    const ColourProgram* current = nullptr;
    if (!pass.colour) {
      const DepthProgram& d = depth_program[roll.on ? 1 : 0];
      const Eigen::Matrix4f MV = to_float(pass.V * M);
      gl.UseProgram(d.id);
      gl.UniformMatrix4fv(d.proj, 1, GL_FALSE, pass.P.data());
      gl.UniformMatrix4fv(d.model_view, 1, GL_FALSE, MV.data());
      set_rolling(d.roll);
    }
    for (const auto& m : meshes) {
      if (pass.colour) bind_material(m.material >= 0 ? &materials[m.material] : nullptr, pass, M, current);
      draw_visible(m, clips);
    }
  }

  // Each stochastically tiled material of the static meshes alone, baked (render/ground_bake.hpp)
  // where it fits; bakes[i] is material i's, if any.
  void bake_grounds(const Scene& scene);
  GLuint bake_ground(const GpuMaterial& live, const GroundBake& plan, const Material& m);
  std::vector<std::optional<GroundBake>> bakes;

  // The colour program of one [rolling][shadowed][stochastic] triple, with its uniform locations.
  ColourProgram make_colour_program(bool rolling, bool shadowed, bool stochastic);
  // p's uniform locations by name (-1 for those its program lacks).
  void locate_uniforms(ColourProgram& p);
  DepthProgram make_depth_program(bool rolling);
  // The programs of a frame drawn with (rolling) or without a rolling shutter, made once.
  void make_programs(bool rolling);
  // Uploads the view's knots (CameraView::rows) and turns the rolling pass on; off without knots.
  void begin_rolling(const CameraView& view, const Eigen::Matrix4d& lead_model);

  void setup_shadows(int size, const cv::Mat& clouds);
  Eigen::Matrix4f render_shadow_map(const std::vector<Eigen::Matrix4f>& clips_from_world,
                                    const std::optional<Eigen::Matrix4d>& lead_model);
  // Whether the kept map is the one clip space L and these casters draw (the same, bit for bit).
  bool shadow_map_holds(const Eigen::Matrix4d& L, const std::optional<Eigen::Matrix4d>& lead_model) const;

  void check_fbo(const char* what) {
    const GLenum s = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (s != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error(std::string("renderer: ") + what +
                               " framebuffer incomplete (status 0x" + std::to_string(s) + ")");
  }

  Target& target(int w, int h) {
    auto it = targets.find({w, h});
    if (it != targets.end()) return it->second;
    Target t;
    t.w = w;
    t.h = h;
    GLint max_samples = 1;
    gl.GetIntegerv(GL_MAX_SAMPLES, &max_samples);
    t.samples = std::max(1, std::min(info.msaa, static_cast<int>(max_samples)));
    auto renderbuffer = [&](int samples, GLenum internal, GLenum attachment) {
      GLuint x = 0;
      gl.GenRenderbuffers(1, &x);
      gl.BindRenderbuffer(GL_RENDERBUFFER, x);
      gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, internal, w, h);
      gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, x);
      return x;
    };
    gl.GenFramebuffers(1, &t.fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    t.colour = renderbuffer(0, GL_RGBA8, GL_COLOR_ATTACHMENT0);
    t.depth = renderbuffer(0, GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT);
    check_fbo("single-sample");
    if (t.samples > 1) {
      gl.GenFramebuffers(1, &t.ms_fbo);
      gl.BindFramebuffer(GL_FRAMEBUFFER, t.ms_fbo);
      t.ms_colour = renderbuffer(t.samples, GL_RGBA8, GL_COLOR_ATTACHMENT0);
      t.ms_depth = renderbuffer(t.samples, GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT);
      check_fbo("multisample");
    }
    t.rgba.create(h, w, CV_8UC4);
    return targets.emplace(std::make_pair(w, h), std::move(t)).first->second;
  }

  // The depth buffer cleared under scissor rectangle `box` (the whole frame: regions null). With
  // regions, made to reject every fragment (the near plane's depth, the test strict) but in the
  // regions that meet the box, which get the usual clear: a rejected fragment is not shaded, and
  // a region's pixels are drawn as in the whole frame.
  void clear_depth(const cv::Rect& box, const std::vector<cv::Rect>* regions) {
    if (!regions) {
      gl.ClearBufferfv(GL_DEPTH, 0, &depth.clear);
      return;
    }
    const float reject = depth.reversed ? 1.f : 0.f;
    gl.ClearBufferfv(GL_DEPTH, 0, &reject);
    for (const cv::Rect& r : *regions)
      if (const cv::Rect c = r & box; !c.empty()) {
        gl.Scissor(c.x, c.y, c.width, c.height);
        gl.ClearBufferfv(GL_DEPTH, 0, &depth.clear);
      }
    gl.Scissor(box.x, box.y, box.width, box.height);
  }

  // Frames are read from the single-sample framebuffer, rows packed tight.
  void bind_for_reading(const Target& t) {
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t.fbo);
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  }

  // Rectangle r of the bound framebuffer into rgba (CV_8UC4) and d (metric depth, CV_32F), both
  // of r's size (GL's row 0 is image row 0).
  void read_rect(const cv::Rect& r, cv::Mat& rgba, cv::Mat& d) {
    gl.ReadPixels(r.x, r.y, r.width, r.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
    gl.ReadPixels(r.x, r.y, r.width, r.height, GL_DEPTH_COMPONENT, GL_FLOAT, d.data);
    to_metric_depth(d, depth);
  }

  Frame read_whole(Target& t) {
    Frame f;
    f.depth.create(t.h, t.w, CV_32F);
    bind_for_reading(t);
    read_rect(cv::Rect(0, 0, t.w, t.h), t.rgba, f.depth);
    cv::cvtColor(t.rgba, f.rgb, cv::COLOR_RGBA2RGB);
    return f;
  }

  // Each rectangle read back on its own into a frame of zeros.
  Frame read_rects(const Target& t, const std::vector<cv::Rect>& rects) {
    Frame f;
    f.rgb = cv::Mat::zeros(t.h, t.w, CV_8UC3);
    f.depth = cv::Mat::zeros(t.h, t.w, CV_32F);
    bind_for_reading(t);
    for (const cv::Rect& r : rects) {
      cv::Mat rgba(r.height, r.width, CV_8UC4), d(r.height, r.width, CV_32F);
      read_rect(r, rgba, d);
      cv::Mat rgb = f.rgb(r);
      cv::cvtColor(rgba, rgb, cv::COLOR_RGBA2RGB);
      d.copyTo(f.depth(r));
    }
    return f;
  }

  void release() {
    for (auto& [k, t] : targets) {
      GLuint fbos[2] = {t.fbo, t.ms_fbo};
      GLuint rbs[4] = {t.colour, t.depth, t.ms_colour, t.ms_depth};
      gl.DeleteFramebuffers(2, fbos);
      gl.DeleteRenderbuffers(4, rbs);
    }
    for (auto* list : {&static_meshes, &lead_meshes, &body_meshes})
      for (auto& m : *list) {
        gl.DeleteVertexArrays(1, &m.vao);
        gl.DeleteBuffers(1, &m.vbo);
        gl.DeleteBuffers(1, &m.ebo);
      }
    for (auto& m : materials) {
      gl.DeleteTextures(1, &m.tex);
      if (m.pieces) gl.DeleteTextures(1, &m.pieces);
    }
    gl.DeleteTextures(1, &white);
    if (roll.tex) gl.DeleteTextures(1, &roll.tex);
    for (auto& by_shadow : colour)
      for (auto& row : by_shadow)
        for (auto& p : row)
          if (p.id) gl.DeleteProgram(p.id);
    for (auto& d : depth_program)
      if (d.id) gl.DeleteProgram(d.id);
    if (sh.map) {
      if (sh.clouds) gl.DeleteTextures(1, &sh.clouds);
      gl.DeleteFramebuffers(1, &sh.fbo);
      gl.DeleteTextures(1, &sh.map);
    }
  }
};

namespace {

template <class Gl>
RollingUniforms rolling_uniforms(Gl& gl, GLuint id) {
  return {gl.GetUniformLocation(id, "u_knots"), gl.GetUniformLocation(id, "u_group"),
          gl.GetUniformLocation(id, "u_row_of"), gl.GetUniformLocation(id, "u_dist"),
          gl.GetUniformLocation(id, "u_k3")};
}

}  // namespace

DepthProgram Renderer::Impl::make_depth_program(bool rolling) {
  DepthProgram d;
  d.id = link({kDepthInputs, rolling ? kRollingEye : kOneViewEye, kDepthVs}, {kDepthFs});
  d.model_view = gl.GetUniformLocation(d.id, "u_model_view");
  d.proj = gl.GetUniformLocation(d.id, "u_proj");
  d.roll = rolling_uniforms(gl, d.id);
  return d;
}

void Renderer::Impl::make_programs(bool rolling) {
  const int r = rolling ? 1 : 0;
  if (depth_program[r].id) return;
  depth_program[r] = make_depth_program(rolling);
  for (int shadowed = 0; shadowed < 2; ++shadowed)
    for (int st = 0; st < 2; ++st)
      if ((!shadowed || info.light.shadows) && (!st || stochastic))
        colour[r][shadowed][st] = make_colour_program(rolling, shadowed, st);
}

ColourProgram Renderer::Impl::make_colour_program(bool rolling, bool shadowed, bool stochastic) {
  ColourProgram p;
  const char* lookup = stochastic ? kStochasticLookup : kImageLookup;
  const char* eye = rolling ? kRollingEye : kOneViewEye;
  // Clouds' shadows only where the world has clouds: a lookup and a varying less a pixel.
  const char* clouds = sh.clouds ? "#define WINGMAN_CLOUDS\n" : "";
  p.id = shadowed ? link({clouds, kVertexInputs, eye, kShadowedVs}, {clouds, lookup, kShadowedFs})
                  : link({kVertexInputs, eye, kSceneVs}, {lookup, kSceneFs});
  p.roll = rolling_uniforms(gl, p.id);
  locate_uniforms(p);
  return p;
}

void Renderer::Impl::locate_uniforms(ColourProgram& p) {
  for (auto [loc, name] : {std::pair{&p.model_view, "u_model_view"}, {&p.proj, "u_proj"}, {&p.model_rot, "u_model_rot"},
                           {&p.tex, "u_tex"}, {&p.to_light, "u_to_light"}, {&p.ambient, "u_ambient"},
                           {&p.bounce, "u_bounce"}, {&p.diffuse, "u_diffuse"}, {&p.unlit, "u_unlit"},
                           {&p.light_from_model, "u_light_from_model"}, {&p.shadow, "u_shadow"},
                           {&p.zero_to_one, "u_zero_to_one"}, {&p.model, "u_model"}, {&p.cloud_tex, "u_clouds"},
                           {&p.cloud_offset, "u_cloud_offset"}, {&p.cloud_period, "u_cloud_period"},
                           {&p.cloud_height, "u_cloud_height"}, {&p.cloud_block, "u_cloud_block"},
                           {&p.cell, "u_cell"}, {&p.aspect, "u_aspect"}, {&p.sharpness, "u_sharpness"},
                           {&p.mean, "u_mean"}, {&p.pieces, "u_pieces"}})
    *loc = gl.GetUniformLocation(p.id, name);
}

void Renderer::Impl::bake_grounds(const Scene& scene) {
  GLint max_side = 0;
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
  bakes.assign(materials.size(), std::nullopt);
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].cell <= 0 || !scene.materials[i].bake) continue;
    const auto uses = [&](const std::vector<Mesh>& meshes) {
      return std::any_of(meshes.begin(), meshes.end(), [&](const Mesh& m) { return m.material == static_cast<int>(i); });
    };
    if (uses(scene.lead_meshes) || uses(scene.body_meshes)) continue;  // on what moves: drawn live
    const Material& src = scene.materials[i];
    const auto plan = plan_ground_bake(uv_box(scene.static_meshes, static_cast<int>(i)), src.texture.cols,
                                       src.texture.rows, max_side);
    if (!plan) continue;
    GpuMaterial baked;
    baked.tex = bake_ground(materials[i], *plan, src);
    baked.unlit = materials[i].unlit;
    gl.DeleteTextures(1, &materials[i].tex);
    gl.DeleteTextures(1, &materials[i].pieces);
    materials[i] = baked;
    bakes[i] = plan;
  }
}

// The live tiling drawn once over the plan's texels (kBakeFs), then filtered as the material is.
GLuint Renderer::Impl::bake_ground(const GpuMaterial& live, const GroundBake& plan, const Material& m) {
  // Half-texel gradients: magnification, so level 0 alone, where the LOD of exactly 0 that the
  // texel spacing gives may be rounded up into level 1.
  const GLuint program = link({kBakeVs}, {"#define WINGMAN_GRADIENT_SCALE 0.5\n", kStochasticLookup, kBakeFs});
  GLuint tex = 0, fbo = 0, vao = 0;
  gl.GenTextures(1, &tex);
  gl.BindTexture(GL_TEXTURE_2D, tex);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, plan.width, plan.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.GenFramebuffers(1, &fbo);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  check_fbo("baked ground");
  gl.GenVertexArrays(1, &vao);
  gl.BindVertexArray(vao);
  gl.Viewport(0, 0, plan.width, plan.height);
  gl.Disable(GL_DEPTH_TEST);
  ColourProgram p;
  p.id = program;
  locate_uniforms(p);
  gl.UseProgram(program);
  const Eigen::Vector2f uv0 = plan.uv0.cast<float>(), texel = plan.density.cwiseInverse().cast<float>();
  gl.Uniform2fv(gl.GetUniformLocation(program, "u_uv0"), 1, uv0.data());
  gl.Uniform2fv(gl.GetUniformLocation(program, "u_texel"), 1, texel.data());
  gl.Uniform1i(p.tex, 0);
  bind_stochastic(p, live);
  gl.BindTexture(GL_TEXTURE_2D, live.tex);
  // Isotropic footprints: anisotropic filtering would change nothing but llvmpipe's path (the
  // image is deleted once baked).
  if (max_aniso > 1) gl.TexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY, 1.f);
  gl.DrawArrays(GL_TRIANGLES, 0, 3);
  gl.BindVertexArray(0);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.DeleteFramebuffers(1, &fbo);
  gl.DeleteVertexArrays(1, &vao);
  gl.DeleteProgram(program);
  gl.BindTexture(GL_TEXTURE_2D, tex);
  set_sampling(false, m.mipmaps, m.trilinear, m.anisotropy);
  return tex;
}

bool Renderer::Impl::shadow_map_holds(const Eigen::Matrix4d& L, const std::optional<Eigen::Matrix4d>& lead_model) const {
  return sh.kept && L == sh.L && lead_model == sh.lead && body_models == sh.bodies;
}

void Renderer::Impl::setup_shadows(int size, const cv::Mat& clouds) {
  if (!clouds.empty()) sh.clouds = upload_texture(clouds, true, true, true, 1);
  gl.GenTextures(1, &sh.map);
  gl.BindTexture(GL_TEXTURE_2D, sh.map);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, size, size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float lit[4] = {1, 1, 1, 1};  // outside the map: in the light
  gl.TexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, lit);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  gl.GenFramebuffers(1, &sh.fbo);
  gl.BindFramebuffer(GL_FRAMEBUFFER, sh.fbo);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, sh.map, 0);
  const GLenum none = GL_NONE;
  gl.DrawBuffers(1, &none);
  gl.ReadBuffer(GL_NONE);
  check_fbo("shadow map");
}

// The sun's orthographic view over what the camera sees: along the light, the receivers' chunks
// in the camera's view bound the map sideways (a caster's shadow lies where the caster does in
// this projection) and every chunk bounds its depth, so casters outside the view still cast.
// Returns the sun's clip space from the world.
Eigen::Matrix4f Renderer::Impl::render_shadow_map(const std::vector<Eigen::Matrix4f>& clips_from_world,
                                                  const std::optional<Eigen::Matrix4d>& lead_model) {
  const Eigen::Vector3d d = info.light.direction.normalized();
  const Eigen::Vector3d e1 = d.unitOrthogonal(), e2 = d.cross(e1);
  Eigen::Matrix3d R;
  R << e1.transpose(), e2.transpose(), d.transpose();  // world to light: x, y across, z along
  Eigen::AlignedBox2d side;
  double z0 = INFINITY, z1 = -INFINITY;
  auto add = [&](const Eigen::AlignedBox3f& box, const Eigen::Matrix4d& M, bool in_view_of_camera) {
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d p = R * (M * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).cast<double>().homogeneous()).head<3>();
      z0 = std::min(z0, p.z()), z1 = std::max(z1, p.z());
      if (in_view_of_camera) side.extend(p.head<2>());
    }
  };
  auto seen = [&](const Eigen::AlignedBox3f& box) {
    return std::any_of(clips_from_world.begin(), clips_from_world.end(),
                       [&](const Eigen::Matrix4f& clip) { return in_view(box, clip); });
  };
  for (const auto& m : static_meshes)
    for (const Chunk& c : m.chunks) add(c.box, Eigen::Matrix4d::Identity(), seen(c.box));
  if (lead_model)
    for (const auto& m : lead_meshes)
      for (const Chunk& c : m.chunks) add(c.box, *lead_model, true);
  for (const Eigen::Matrix4d& M : body_models)  // casters: their shadows bound the map where they fall
    for (const auto& m : body_meshes)
      for (const Chunk& c : m.chunks) add(c.box, M, false);
  if (side.isEmpty()) side.extend(Eigen::Vector2d(0, 0)).extend(Eigen::Vector2d(1, 1));
  const double zlo = z0 - 1, zhi = z1 + 1;  // a metre of room at either end
  Eigen::Matrix4d L = Eigen::Matrix4d::Identity();
  const Eigen::Vector2d lo = side.min(), span = (side.max() - side.min()).cwiseMax(1e-3);
  L.block<1, 3>(0, 0) = 2 / span.x() * R.row(0);
  L(0, 3) = -2 * lo.x() / span.x() - 1;
  L.block<1, 3>(1, 0) = 2 / span.y() * R.row(1);
  L(1, 3) = -2 * lo.y() / span.y() - 1;
  const double zs = depth.reversed ? 1 / (zhi - zlo) : 2 / (zhi - zlo);  // NDC z in [0, 1] or [-1, 1]
  L.block<1, 3>(2, 0) = zs * R.row(2);
  L(2, 3) = depth.reversed ? -zlo * zs : -zlo * zs - 1;
  const Eigen::Matrix4f Lf = to_float(L);
  if (shadow_map_holds(L, lead_model)) return Lf;
  const int size = info.light.shadow_map;
  sh.kept = true, sh.L = L, sh.lead = lead_model, sh.bodies = body_models;
  ++sh.drawn;
  gl.BindFramebuffer(GL_FRAMEBUFFER, sh.fbo);
  gl.Viewport(0, 0, size, size);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  const float far_depth = 1;
  gl.ClearBufferfv(GL_DEPTH, 0, &far_depth);
  gl.Enable(GL_POLYGON_OFFSET_FILL);
  gl.PolygonOffset(2.0f, 4.0f);  // against self-shadowing of the lit surfaces
  draw_scene(false, Lf, Eigen::Matrix4d::Identity(), lead_model);
  gl.Disable(GL_POLYGON_OFFSET_FILL);
  return Lf;
}

Renderer::Renderer(GlContext& ctx, const Scene& scene) : ctx_(ctx), impl_(std::make_unique<Impl>()) {
  ctx_.make_current();
  Impl& I = *impl_;
  I.gl.load(ctx_);
  auto& gl = I.gl;
  while (gl.GetError() != GL_NO_ERROR) {
  }
  gl.GetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &I.max_aniso);
  if (gl.GetError() != GL_NO_ERROR) I.max_aniso = 1;  // no anisotropic filtering here
  I.info.light = scene.light;
  I.info.sky = scene.sky;
  I.info.near = scene.near;
  I.info.far = scene.far;
  I.info.msaa = scene.msaa;
  I.depth = depth_map(scene.near, scene.far, gl.ClipControl != nullptr);
  I.sky = sky_light(scene.light, scene.light.direction);
  if (scene.light.shadows) I.setup_shadows(scene.light.shadow_map, scene.clouds);
  I.white =
      I.upload_texture(cv::Mat(1, 1, CV_8UC3, cv::Scalar(255, 255, 255)), true, false, false, 1);
  for (const auto& m : scene.materials) I.materials.push_back(I.upload_material(m));
  I.bake_grounds(scene);
  for (const GpuMaterial& m : I.materials) I.stochastic = I.stochastic || m.cell > 0;
  I.make_programs(false);
  for (const auto& m : scene.static_meshes)
    if (!m.indices.empty()) {
      const auto& bake = m.material >= 0 ? I.bakes[static_cast<std::size_t>(m.material)] : std::nullopt;
      I.static_meshes.push_back(I.upload_mesh(m, kChunkSize, bake ? &*bake : nullptr));
    }
  for (const auto& m : scene.lead_meshes)
    if (!m.indices.empty()) I.lead_meshes.push_back(I.upload_mesh(m, 0));
  for (const auto& m : scene.body_meshes)
    if (!m.indices.empty()) I.body_meshes.push_back(I.upload_mesh(m, 0));
  if (const GLenum e = gl.GetError(); e != GL_NO_ERROR)
    throw std::runtime_error("renderer: OpenGL error 0x" + std::to_string(e) + " while uploading the scene");
}

int Renderer::shadow_maps_drawn() const { return impl_->sh.drawn; }

Renderer::~Renderer() {
  try {
    ctx_.make_current();
    impl_->release();
  } catch (...) {
    // The context is going away with us anyway.
  }
}

Eigen::Matrix4d Renderer::projection(double fx, double fy, double cx, double cy, int w, int h,
                                     double n, double f, bool reversed_z) {
  // Clip w = z (OpenCV camera looks along +z). Window x = u + 0.5 puts u = fx x/z + cx at the
  // centre of pixel column u; window y = v + 0.5 makes GL's row 0 the image's top row.
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 2 * fx / w;
  P(0, 2) = 2 * (cx + 0.5) / w - 1;
  P(1, 1) = 2 * fy / h;
  P(1, 2) = 2 * (cy + 0.5) / h - 1;
  // Clip z = a z + b: NDC z runs from -1 at near to 1 at far, or (reversed, for a [0, 1] clip
  // range) from 1 at near to 0 at far; see DepthMap.
  const DepthMap m = depth_map(n, f, reversed_z);
  P(2, 2) = reversed_z ? m.alpha : (f + n) / (f - n);
  P(2, 3) = reversed_z ? m.beta : -2 * f * n / (f - n);
  P(3, 2) = 1;
  return P;
}

namespace {

// A model's frame in the world: at `pose`'s position, turned by its yaw about world z.
Eigen::Matrix4d model_matrix(const LeadPose& pose) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  M.topLeftCorner<3, 3>() << c, -s, 0, s, c, 0, 0, 0, 1;
  M.topRightCorner<3, 1>() = pose.position;
  return M;
}

// World to the camera frame.
Eigen::Matrix4d view_matrix(const geometry::CameraPose& pose) {
  Eigen::Matrix4d V = Eigen::Matrix4d::Identity();
  V.topLeftCorner<3, 3>() = pose.R_CW;
  V.topRightCorner<3, 1>() = -pose.R_CW * pose.position;
  return V;
}

}  // namespace

void Renderer::Impl::begin_rolling(const CameraView& view, const Eigen::Matrix4d& lead_model) {
  roll.on = false;
  if (view.rows.empty()) return;
  make_programs(true);
  const std::size_t knots = std::max<std::size_t>(view.rows.size(), 2), groups = 2 + body_models.size();
  roll.model_view.assign(groups, std::vector<Eigen::Matrix4d>(knots));
  std::vector<float> texels(groups * knots * 12);
  for (std::size_t k = 0; k < knots; ++k) {
    const RowKnot& knot = view.rows[std::min(k, view.rows.size() - 1)];
    const Eigen::Matrix4d V = view_matrix(knot.pose);
    for (std::size_t g = 0; g < groups; ++g) {
      Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
      if (g == 1) M = knot.lead ? model_matrix(*knot.lead) : lead_model;
      if (g >= 2) M = g - 2 < knot.bodies.size() ? model_matrix(knot.bodies[g - 2]) : body_models[g - 2];
      roll.model_view[g][k] = V * M;
      const Eigen::Matrix4f mv = to_float(V * M);
      float* t = &texels[(g * knots + k) * 12];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) t[4 * r + c] = mv(r, c);
    }
  }
  gl.ActiveTexture(GL_TEXTURE4);
  if (!roll.tex) {
    gl.GenTextures(1, &roll.tex);
    gl.BindTexture(GL_TEXTURE_2D, roll.tex);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  gl.BindTexture(GL_TEXTURE_2D, roll.tex);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, static_cast<GLsizei>(3 * knots), static_cast<GLsizei>(groups), 0,
                GL_RGBA, GL_FLOAT, texels.data());
  gl.ActiveTexture(GL_TEXTURE0);
  const geometry::PinholeCamera& cam = view.camera;
  const geometry::Distortion& d = cam.distortion();
  roll.row_of = Eigen::Vector4d(cam.fy(), cam.cy(), (cam.height() - 1.0) / static_cast<double>(knots - 1),
                                static_cast<double>(knots - 1))
                    .cast<float>();
  roll.dist = Eigen::Vector4d(d.k1, d.k2, d.p1, d.p2).cast<float>();
  roll.k3 = static_cast<float>(d.k3);
  roll.on = true;
}

Frame Renderer::render_pinhole(double fx, double fy, double cx, double cy, int w, int h,
                               const CameraView& view, const std::optional<LeadPose>& lead,
                               const Regions* regions) {
  ctx_.make_current();
  Impl& I = *impl_;
  auto& gl = I.gl;
  Target& t = I.target(w, h);
  const Eigen::Matrix4f P =
      to_float(projection(fx, fy, cx, cy, w, h, I.info.near, I.info.far, I.depth.reversed));
  const Eigen::Matrix4d V = view_matrix(view.pose);
  std::optional<Eigen::Matrix4d> lead_model;
  if (lead && !I.lead_meshes.empty()) lead_model = model_matrix(*lead);
  I.body_models.clear();
  if (!I.body_meshes.empty())
    for (const LeadPose& b : view.bodies) I.body_models.push_back(model_matrix(b));

  if (I.depth.reversed) gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  std::optional<Eigen::Matrix4f> light;
  I.sh.time = view.time;
  I.begin_rolling(view, lead_model ? *lead_model : Eigen::Matrix4d::Identity());
  if (I.sh.map) {
    // Receivers in view of the shadow's views, or of this view's first, middle and last rows
    // under a rolling shutter.
    std::vector<Eigen::Matrix4f> clips =
        I.roll.on ? I.rolling_clips(P, 0) : std::vector<Eigen::Matrix4f>{P * to_float(V)};
    if (!view.shadow_views.empty()) clips = shadow_clips(view.shadow_views);
    const bool rolling = std::exchange(I.roll.on, false);  // the sun's view is one view
    light = I.render_shadow_map(clips, lead_model);
    I.roll.on = rolling;
  }
  gl.Viewport(0, 0, w, h);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(I.depth.reversed ? GL_GREATER : GL_LESS);
  gl.Disable(GL_CULL_FACE);  // the y-flipped projection mirrors the winding; draw both faces
  const float sky[4] = {static_cast<float>(I.info.sky.x()), static_cast<float>(I.info.sky.y()),
                        static_cast<float>(I.info.sky.z()), 1.f};
  // Each region (or the whole image) is cleared and drawn under its scissor rectangle; the
  // rasteriser skips the tiles outside it.
  const std::vector<cv::Rect> whole = {cv::Rect(0, 0, w, h)};
  const std::vector<cv::Rect>& rects = regions ? regions->draw : whole;
  if (regions) gl.Enable(GL_SCISSOR_TEST);
  for (const cv::Rect& r : rects) {
    gl.Scissor(r.x, r.y, r.width, r.height);
    if (regions) I.cull = region_from_clip(r, w, h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, t.samples > 1 ? t.ms_fbo : t.fbo);
    if (t.samples > 1) gl.Enable(GL_MULTISAMPLE);
    gl.ClearBufferfv(GL_COLOR, 0, sky);
    I.clear_depth(r, regions ? &regions->read : nullptr);
    I.draw_scene(true, P, V, lead_model, light ? &*light : nullptr);
    if (t.samples > 1) {
      // Colour: the samples averaged by the blit. Depth: a single-sample pass (kDepthVs).
      gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t.ms_fbo);
      gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, t.fbo);
      gl.BlitFramebuffer(r.x, r.y, r.x + r.width, r.y + r.height, r.x, r.y, r.x + r.width, r.y + r.height,
                         GL_COLOR_BUFFER_BIT, GL_NEAREST);
      gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
      I.clear_depth(r, regions ? &regions->read : nullptr);
      gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      I.draw_scene(false, P, V, lead_model);
      gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }
  }
  if (regions) gl.Disable(GL_SCISSOR_TEST);
  I.cull = Eigen::Matrix4f::Identity();
  I.roll.on = false;
  gl.BindVertexArray(0);
  Frame f = regions ? I.read_rects(t, regions->read) : I.read_whole(t);
  if (const GLenum e = gl.GetError(); e != GL_NO_ERROR)
    throw std::runtime_error("renderer: OpenGL error 0x" + std::to_string(e) + " while rendering");
  return f;
}

namespace {

// The lead model's box projected into the pinhole image (padded by a pixel), or, when part of it
// is behind the camera, the image with a margin; nothing when all of it is.
std::optional<cv::Rect> silhouette_window(const Eigen::AlignedBox3f& box, const Eigen::Matrix4d& M,
                                          const CameraView& view, double near, int max_side) {
  const auto& cam = view.camera;
  const int margin = max_side / 4;
  const cv::Rect around(-margin, -margin, cam.width() + 2 * margin, cam.height() + 2 * margin);
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  int in_front = 0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p_W = (M * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(i))
                                         .cast<double>()
                                         .homogeneous())
                                    .head<3>();
    const Eigen::Vector3d p = view.pose.R_CW * (p_W - view.pose.position);
    if (p.z() <= near) continue;
    ++in_front;
    const double u = cam.fx() * p.x() / p.z() + cam.cx(), v = cam.fy() * p.y() / p.z() + cam.cy();
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  }
  if (in_front == 0) return std::nullopt;
  if (in_front < 8) return around;
  // Clamped before the cast: a corner just past the near plane projects far out.
  auto clamp = [&](double x) { return std::clamp(x, -1e7, 1e7); };
  const int x0 = static_cast<int>(std::floor(clamp(u0))) - 1, y0 = static_cast<int>(std::floor(clamp(v0))) - 1;
  cv::Rect w(x0, y0, static_cast<int>(std::ceil(clamp(u1))) + 2 - x0, static_cast<int>(std::ceil(clamp(v1))) + 2 - y0);
  if (w.width > max_side || w.height > max_side) w &= around;
  if (w.empty()) return std::nullopt;
  return w;
}

}  // namespace

std::optional<LeadSilhouette> Renderer::lead_silhouette(const CameraView& view, const LeadPose& lead,
                                                        int max_side) {
  Impl& I = *impl_;
  if (I.lead_meshes.empty()) return std::nullopt;
  Eigen::AlignedBox3f box;
  for (const GpuMesh& m : I.lead_meshes)
    for (const Chunk& c : m.chunks) box.extend(c.box);
  const Eigen::Matrix4d M = model_matrix(lead);
  const auto window = silhouette_window(box, M, view, I.info.near, max_side);
  if (!window) return std::nullopt;
  ctx_.make_current();
  auto& gl = I.gl;
  const int w = window->width, h = window->height;
  int side = 64;  // targets by powers of two: a few sizes over a flight, each made once
  while (side < std::max(w, h)) side *= 2;
  Target& t = I.target(side, side);
  const auto& cam = view.camera;
  const Eigen::Matrix4f P = to_float(projection(cam.fx(), cam.fy(), cam.cx() - window->x, cam.cy() - window->y,
                                                w, h, I.info.near, I.info.far, I.depth.reversed));
  Eigen::Matrix4d V = Eigen::Matrix4d::Identity();
  V.topLeftCorner<3, 3>() = view.pose.R_CW;
  V.topRightCorner<3, 1>() = -view.pose.R_CW * view.pose.position;
  if (I.depth.reversed) gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  gl.Viewport(0, 0, w, h);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(I.depth.reversed ? GL_GREATER : GL_LESS);
  gl.Disable(GL_CULL_FACE);
  gl.ClearBufferfv(GL_DEPTH, 0, &I.depth.clear);
  gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  I.draw_meshes(Impl::Pass{false, P, V, nullptr}, I.lead_meshes, M, 1);
  gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  gl.BindVertexArray(0);
  LeadSilhouette s;
  s.window = *window;
  s.depth.create(h, w, CV_32F);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t.fbo);
  gl.ReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, s.depth.data);
  to_metric_depth(s.depth, I.depth);
  if (const GLenum e = gl.GetError(); e != GL_NO_ERROR)
    throw std::runtime_error("renderer: OpenGL error 0x" + std::to_string(e) + " while drawing the lead alone");
  return s;
}

// Remap tables from the distorted image to a wider pinhole canvas.
struct Renderer::Undistort {
  double cx = 0, cy = 0;  // principal point on the canvas
  int w = 0, h = 0;       // canvas size
  cv::Mat map1, map2;     // fixed-point maps for cv::remap (bilinear)
  cv::Mat nearest_x, nearest_y;  // float maps for depth (nearest)
};

const Renderer::Undistort& Renderer::undistort(const geometry::PinholeCamera& cam) {
  const auto& d = cam.distortion();
  const auto key = std::make_tuple(cam.fx(), cam.fy(), cam.cx(), cam.cy(), cam.width(),
                                   cam.height(), d.k1, d.k2, d.p1, d.p2, d.k3);
  auto& u = undistort_[key];
  if (u) return *u;
  u = std::make_shared<Undistort>();
  cv::Mat mx(cam.height(), cam.width(), CV_32F), my(cam.height(), cam.width(), CV_32F);
  double umin = 0, umax = cam.width() - 1, vmin = 0, vmax = cam.height() - 1;
  for (int r = 0; r < cam.height(); ++r)
    for (int c = 0; c < cam.width(); ++c) {
      const Eigen::Vector2d xn = cam.unproject_normalised(Eigen::Vector2d(c, r));
      const double pu = cam.fx() * xn.x() + cam.cx(), pv = cam.fy() * xn.y() + cam.cy();
      mx.at<float>(r, c) = static_cast<float>(pu);
      my.at<float>(r, c) = static_cast<float>(pv);
      umin = std::min(umin, pu), umax = std::max(umax, pu);
      vmin = std::min(vmin, pv), vmax = std::max(vmax, pv);
    }
  // Canvas covering every pixel the distorted image samples (at most 3x the image).
  umin = std::max(std::floor(umin) - 2, -1.0 * cam.width());
  vmin = std::max(std::floor(vmin) - 2, -1.0 * cam.height());
  umax = std::min(std::ceil(umax) + 2, 2.0 * cam.width());
  vmax = std::min(std::ceil(vmax) + 2, 2.0 * cam.height());
  u->w = static_cast<int>(umax - umin) + 1;
  u->h = static_cast<int>(vmax - vmin) + 1;
  u->cx = cam.cx() - umin;
  u->cy = cam.cy() - vmin;
  mx -= static_cast<float>(umin);
  my -= static_cast<float>(vmin);
  u->nearest_x = mx;
  u->nearest_y = my;
  cv::convertMaps(mx, my, u->map1, u->map2, CV_16SC2);
  return *u;
}

std::vector<Eigen::Matrix4f> Renderer::shadow_clips(
    const std::vector<std::pair<geometry::PinholeCamera, geometry::CameraPose>>& views) {
  std::vector<Eigen::Matrix4f> clips;
  for (const auto& [cam, pose] : views) {
    double cx = cam.cx(), cy = cam.cy();
    int w = cam.width(), h = cam.height();
    if (!cam.distortion().is_zero()) {  // the canvas a distorted camera is drawn on
      const Undistort& u = undistort(cam);
      cx = u.cx, cy = u.cy, w = u.w, h = u.h;
    }
    clips.push_back(to_float(projection(cam.fx(), cam.fy(), cx, cy, w, h, impl_->info.near, impl_->info.far,
                                        impl_->depth.reversed) *
                             view_matrix(pose)));
  }
  return clips;
}

Frame Renderer::render(const CameraView& view, const std::optional<LeadPose>& lead) {
  const auto& cam = view.camera;
  if (cam.distortion().is_zero())
    return render_pinhole(cam.fx(), cam.fy(), cam.cx(), cam.cy(), cam.width(), cam.height(), view,
                          lead);
  const Undistort& u = undistort(cam);
  const Frame wide = render_pinhole(cam.fx(), cam.fy(), u.cx, u.cy, u.w, u.h, view, lead);
  Frame f;
  cv::remap(wide.rgb, f.rgb, u.map1, u.map2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(wide.depth, f.depth, u.nearest_x, u.nearest_y, cv::INTER_NEAREST,
            cv::BORDER_CONSTANT);
  return f;
}

namespace {
// What one more draw of the scene costs, in pixels drawn: each scissored draw runs the scene's
// vertices and binning again (bench_render BM_RegionsEgl: about 0.7 ms of CPU a draw on llvmpipe
// against 0.08 us a pixel).
constexpr double kDrawCostPx = 9000;

// Rectangles to draw that cover the regions: two are drawn as their bounding box whenever that
// costs no more than drawing them apart, until no pair does (greedy, the largest saving first).
// A box's pixels outside the regions are masked (Impl::clear_depth) but priced as drawn ones:
// pricing them at 0.07 to 0.6 of a drawn pixel merged more and measured slower in BM_RegionsEgl.
std::vector<cv::Rect> draw_rectangles(std::vector<cv::Rect> rects) {
  for (;;) {
    double best = 0;
    std::size_t bi = 0, bj = 0;
    for (std::size_t i = 0; i < rects.size(); ++i)
      for (std::size_t j = i + 1; j < rects.size(); ++j) {
        const double gain = rects[i].area() + rects[j].area() + kDrawCostPx - (rects[i] | rects[j]).area();
        if (gain > best) best = gain, bi = i, bj = j;
      }
    if (best <= 0) return rects;
    rects[bi] |= rects[bj];
    rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(bj));
  }
}
}  // namespace

Frame Renderer::render_regions(const CameraView& view, const std::optional<LeadPose>& lead,
                               const std::vector<cv::Rect>& regions) {
  const auto& cam = view.camera;
  if (!cam.distortion().is_zero()) return render(view, lead);
  const cv::Rect image(0, 0, cam.width(), cam.height());
  Regions rs;
  for (const cv::Rect& r : regions)
    if (const cv::Rect c = r & image; !c.empty()) rs.read.push_back(c);
  rs.draw = draw_rectangles(rs.read);
  return render_pinhole(cam.fx(), cam.fy(), cam.cx(), cam.cy(), cam.width(), cam.height(), view, lead, &rs);
}

Frame Renderer::render_rows(const CameraView& view, const std::optional<LeadPose>& lead, int row0, int rows) {
  const auto& cam = view.camera;
  if (row0 < 0 || rows < 1 || row0 + rows > cam.height())
    throw std::invalid_argument("render_rows: rows " + std::to_string(row0) + " + " + std::to_string(rows) +
                                " outside an image of " + std::to_string(cam.height()));
  if (row0 == 0 && rows == cam.height()) return render(view, lead);
  // The band is an image of its own whose principal point sits row0 rows higher.
  if (cam.distortion().is_zero())
    return render_pinhole(cam.fx(), cam.fy(), cam.cx(), cam.cy() - row0, cam.width(), rows, view, lead);
  const Undistort& u = undistort(cam);
  const cv::Range band(row0, row0 + rows);
  double lo = 0, hi = 0;
  cv::minMaxLoc(u.nearest_y.rowRange(band), &lo, &hi);
  const int y0 = std::max(0, static_cast<int>(std::floor(lo)) - 1);
  const int y1 = std::min(u.h - 1, static_cast<int>(std::ceil(hi)) + 1);
  const Frame wide = render_pinhole(cam.fx(), cam.fy(), u.cx, u.cy - y0, u.w, y1 - y0 + 1, view, lead);
  const cv::Mat mx = u.nearest_x.rowRange(band), my = u.nearest_y.rowRange(band) - static_cast<float>(y0);
  cv::Mat m1, m2;
  cv::convertMaps(mx, my, m1, m2, CV_16SC2);
  Frame f;
  cv::remap(wide.rgb, f.rgb, m1, m2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(wide.depth, f.depth, mx, my, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  return f;
}

}  // namespace wingman::render
