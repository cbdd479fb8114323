// What the renderer draws, on the CPU side: meshes with per-vertex colour and one material each,
// textures as images, light and sky. build_scene() makes it from a scenario's world section
// (terrain, its texture, scattered objects, the lead's assimp model with its roof cue); tests
// build small scenes by hand. Uploaded once to the GPU by Renderer.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/world.hpp"

namespace wingman::render {

struct Material {
  cv::Mat texture;  // CV_8UC3 or CV_8UC4, RGB(A) order, row 0 at t = 0; empty: plain white
  bool repeat = true;
  bool mipmaps = true;
  double anisotropy = 4;
  bool trilinear = true;  // between mipmap levels; false: the nearest level only (faster)
  bool unlit = false;  // colour shown as is (markers, test targets)
  // Stochastic tiling (world.texture.tiling, render/renderer.cpp kStochasticLookup, its pieces
  // placed by render/piece_table.hpp from the seed): the triangle
  // grid's side as a fraction of the texture's shorter side; 0: the texture as it is.
  double stochastic_cell = 0;
  double blend_sharpness = 8;
  std::uint32_t stochastic_seed = 0;
  bool bake = true;  // stochastic: baked into one texture where it fits (render/ground_bake.hpp)
};

struct Mesh {
  std::vector<float> positions;  // xyz per vertex
  std::vector<float> normals;    // xyz per vertex
  std::vector<float> uvs;        // st per vertex
  std::vector<float> colours;    // rgb per vertex, multiplies the texture
  std::vector<std::uint32_t> indices;
  int material = -1;  // index into Scene::materials, -1: untextured

  std::size_t vertex_count() const { return positions.size() / 3; }
  // Appends one vertex.
  void add(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector2d& uv,
           const Eigen::Vector3d& colour);
  // Appends another mesh's triangles (same material).
  void append(const Mesh& m);
};

struct Scene {
  std::vector<Material> materials;
  std::vector<Mesh> static_meshes;  // world frame
  std::vector<Mesh> lead_meshes;    // lead frame: origin at its reference point, x forward, z up
  // One UAV's body (world.uav_bodies), drawn at each UAV's pose: origin at its bottom centre, x
  // forward, z up. Empty when the team's bodies are off.
  std::vector<Mesh> body_meshes;
  sim::LightSpec light{};
  Eigen::Vector3d sky{0.62, 0.74, 0.88};
  double near = 0.1, far = 1000;
  int msaa = 4;
  cv::Mat clouds;  // CV_8UC1, periodic cloud density over light.clouds.scale metres (empty: none)
};

// Pose of the lead's reference point: position in the world and heading about world z.
using LeadPose = sim::LeadPose;

// Where a model from a file goes: scaled to `height`, its up axis made z, the centre of its
// bounding box's top face (on_top) or bottom face at `offset`. `what` names it in errors.
struct ModelPlacement {
  std::string what;
  std::string up = "z";
  double height = 1;
  bool on_top = true;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

// A model from any format assimp reads, placed as `place` says; its textured materials join
// scene.materials (sampled as the lead model's are). Throws std::runtime_error naming the file
// when it is missing, not a model, or refers to a missing texture.
std::vector<Mesh> load_model(const ModelPlacement& place, const std::string& path, const Material& sampling,
                             Scene& scene);

// The lead model from any format assimp reads, scaled to `height`, its up axis made z, its
// top-centre moved to the origin; with the cue on its roof. Throws std::runtime_error naming the
// file when it is missing, not a model, or refers to a missing texture. Its materials sample their
// textures as `sampling` does between mipmap levels (build_scene passes the ground's); the cue
// takes its anisotropy too, the model's own faces none (scene.cpp, kSolidAnisotropy).
void load_lead_model(const sim::LeadModelSpec& spec, const std::string& path, const Material& sampling,
                     Scene& scene);

// The whole world a scenario describes (sim::describe_world).
Scene build_scene(const sim::WorldDescription& world);

}  // namespace wingman::render
