// The rendered world of a scenario (`world:` section, docs/rendering.md): terrain, its texture,
// scattered objects, the lead's model and its visual cue, light and image effects. The spec is
// plain data; TerrainModel and scatter_objects() turn it into heights and object placements that
// the renderer draws and anyone else (tests, a replay) can query without a GL context.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/settings.hpp"

namespace wingman::sim {

struct Scenario;
class OpenLoopTruth;
class Truth;

struct TerrainSpec {
  double extent = 0;          // m, side of the square terrain; 0: the flight's extent plus margin
  double margin = 60;         // m around the flight when extent is 0 (a nadir camera at 17 m sees +-42 m)
  double mean_height = 0;     // m (an aerial lead; around a ground lead the land follows its road)
  double relief = 1.5;        // m, peak amplitude of the seeded undulation
  double relief_scale = 40;   // m, wavelength of the largest undulation
  double resolution = 2;      // m between mesh vertices
  double road_half_width = 3;  // m of flat ground under a ground lead's path
  double road_blend = 8;       // m over which the terrain returns to its own relief

  template <class V>
  void visit(V& v) {
    v("extent", extent, geometry::ge(0));
    v("margin", margin, geometry::ge(0));
    v("mean_height", mean_height);
    v("relief", relief, geometry::ge(0));
    v("relief_scale", relief_scale, geometry::gt(0));
    v("resolution", resolution, geometry::in(0.1, 50));
    v("road_half_width", road_half_width, geometry::ge(0));
    v("road_blend", road_blend, geometry::gt(0));
  }
};

struct TextureSpec {
  enum class Type { Image, Procedural };
  enum class Mode { Tiled, Stretched };
  enum class Filter { Trilinear, Bilinear };
  enum class Tiling { Stochastic, Repeat };
  Type type = Type::Image;
  std::string image = "aerial/freetown_drone_nadir.jpg";  // scenario dir, then assets/
  Mode mode = Mode::Tiled;
  double tile_size = 60;     // m covered by one copy of the image (tiled)
  // m: the world point of one copy's top-left corner (tiled), so that a flight can lie inside one
  // copy of a large image and see no repetition.
  double origin_x = 0, origin_y = 0;
  // How a tiled texture fills a world larger than one copy (docs/rendering.md, The world):
  // stochastic (the default) lays a triangle grid over the ground and shows at each of its vertices
  // a piece of the image, blended across the cells with the image's variance kept (Heitz & Neyret
  // 2018), the pieces placed so that nearby vertices never show the same ground a short way apart
  // (render/piece_table.hpp), so that no copy, lattice or seam of the image repeats; repeat tiles
  // the image as it is (for a flight that stays inside one copy of a large image).
  // `cell`: the grid's side as a fraction of the image's shorter side; `blend_sharpness`: the
  // power of the blend weights (1: linear blend; higher: narrower transitions).
  Tiling tiling = Tiling::Stochastic;
  double cell = 0.25;
  double blend_sharpness = 8;
  // Stochastic tiling baked once per world into one texture over the ground, at the image's texel
  // density (render/ground_bake.hpp: one lookup a pixel where the live tiling takes three); false,
  // or a ground too large for the bake, draws it live.
  bool bake = true;
  double detail_min = 0.02;  // m, finest and coarsest detail of the procedural texture
  double detail_max = 0.2;
  int size = 2048;           // px of the procedural texture (one tile, detail_min per texel)
  // Max anisotropic filtering of the ground and the cue (solids never take it); 1 disables it.
  // A nadir camera of 75 deg sees the ground at most 37 deg off-axis, a footprint 1.25 times
  // longer than wide: 1 (the default) loses nothing; the paper's 136 deg camera reaches 2.7,
  // where 4 sharpens the image's edges at twice the rendering time (docs/rendering.md).
  double anisotropy = 1;
  // Minification between mipmap levels: trilinear blends the two nearest levels; bilinear samples
  // the nearest one only (GL_LINEAR_MIPMAP_NEAREST), a quarter less rendering time on llvmpipe,
  // with a visible step in sharpness where the level changes (docs/rendering.md, Speed).
  Filter filter = Filter::Trilinear;

  template <class V>
  void visit(V& v) {
    v.choice("type", type, {{"image", Type::Image}, {"procedural", Type::Procedural}});
    v("image", image);
    v.choice("mode", mode, {{"tiled", Mode::Tiled}, {"stretched", Mode::Stretched}});
    v("tile_size", tile_size, geometry::gt(0));
    v("origin_x", origin_x);
    v("origin_y", origin_y);
    v.choice("tiling", tiling, {{"stochastic", Tiling::Stochastic}, {"repeat", Tiling::Repeat}});
    v("cell", cell, geometry::in(0.05, 0.45));
    v("blend_sharpness", blend_sharpness, geometry::in(1, 64));
    v("bake", bake);
    v("detail_min", detail_min, geometry::gt(0));
    v("detail_max", detail_max, geometry::gt(0));
    v.check("detail_max", detail_max >= detail_min, "must be at least detail_min");
    v("size", size, geometry::in(16, 8192));
    v("anisotropy", anisotropy, geometry::in(1, 64));
    v.choice("filter", filter, {{"trilinear", Filter::Trilinear}, {"bilinear", Filter::Bilinear}});
  }
};

struct ObjectsSpec {
  double boulders = 25;   // per hectare
  double trees = 12;
  double buildings = 2;
  double clearance = 8;   // m kept free on both sides of the lead's path

  template <class V>
  void visit(V& v) {
    v("boulders", boulders, geometry::in(0, 1000));
    v("trees", trees, geometry::in(0, 1000));
    v("buildings", buildings, geometry::in(0, 1000));
    v("clearance", clearance, geometry::ge(0));
  }
};

struct LeadModelSpec {
  enum class Kind { Ground, Aerial };
  enum class Cue { Aruco, Panel, None };
  std::string model = "models/cesium_milk_truck/CesiumMilkTruck.glb";
  Kind kind = Kind::Ground;  // ground: the terrain follows the lead's height along its path
  double height = 2.6;       // m, the model is scaled to this height
  std::string up = "y";      // the model's up axis: y (glTF) or z (Blender, CAD)
  double yaw_offset = 0;     // rad, added to the heading so the model's front points forward
  Cue cue = Cue::Aruco;
  int aruco_id = 0;                 // from DICT_4X4_50
  double marker_size = 1.8;         // m, the black square of the marker (or the panel's side)
  Eigen::Vector3d panel_colour{1.0, 0.0, 1.0};  // cue: panel

  template <class V>
  void visit(V& v) {
    v("model", model);
    v.choice("kind", kind, {{"ground", Kind::Ground}, {"aerial", Kind::Aerial}});
    v("height", height, geometry::gt(0));
    v.choice("up", up, {{"y", std::string("y")}, {"z", std::string("z")}});
    v("yaw_offset", yaw_offset);
    v.choice("cue", cue, {{"aruco", Cue::Aruco}, {"panel", Cue::Panel}, {"none", Cue::None}});
    v("aruco_id", aruco_id, geometry::in(0, 49));
    v("marker_size", marker_size, geometry::gt(0));
    v("panel_colour", panel_colour, geometry::in(0, 1));  // RGB
  }
};

// The sun from a place and a time (sim/sun.hpp), instead of a fixed direction.
struct SunSpec {
  bool enabled = false;
  double latitude = 8.48;     // deg north: Freetown, where the default ground was flown
  double longitude = -13.23;  // deg east
  double day_of_year = 80;    // 1-366 (80: the March equinox)
  double time_utc = 10.5;     // h

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("latitude", latitude, geometry::in(-90, 90));
    v("longitude", longitude, geometry::in(-180, 180));
    v("day_of_year", day_of_year, geometry::in(1, 366));
    v("time_utc", time_utc, geometry::in(0, 24));
  }
};

// Clouds between the sun and the ground: their shadows, drifting with the wind (render/renderer.cpp,
// the shadowed program). A seeded periodic field, thresholded to `cover`.
struct CloudSpec {
  double cover = 0;          // fraction of the sky covered (0: none)
  double scale = 150;        // m across a cloud, roughly
  double height = 1000;      // m above z = 0 of the cloud layer
  Eigen::Vector3d wind{4, 1, 0};  // m/s (z unused)
  double transmission = 0.35;  // of the direct sun through a cloud
  double softness = 0.15;    // of a cloud's edge, in the field's units (0-1)

  template <class V>
  void visit(V& v) {
    v("cover", cover, geometry::in(0, 1));
    v("scale", scale, geometry::gt(0));
    v("height", height, geometry::gt(0));
    v("wind", wind);
    v("transmission", transmission, geometry::in(0, 1));
    v("softness", softness, geometry::in(0.001, 1));
  }
};

// Light from the sky and the ground besides the sun's beam (docs/rendering.md, Light). constant:
// `ambient` and `diffuse` as given, white, on every surface alike. clear_sky: both follow the sun's
// elevation through a clear atmosphere (render/skylight.hpp): the beam dims and reddens with the
// air mass, the sky light dims and stays blue, and a surface sees the sky over the part of its
// hemisphere facing up and the ground (of `ground_albedo`) over the rest; `ambient` and `diffuse`
// are then their values for the sun at the zenith.
struct SkylightSpec {
  enum class Model { Constant, ClearSky };
  Model model = Model::Constant;
  double ground_albedo = 0.15;
  double aerosol_depth = 0.1;  // aerosol optical depth at 550 nm (0.05 very clear, 0.3 hazy)

  template <class V>
  void visit(V& v) {
    v.choice("model", model, {{"constant", Model::Constant}, {"clear_sky", Model::ClearSky}});
    v("ground_albedo", ground_albedo, geometry::in(0, 1));
    v("aerosol_depth", aerosol_depth, geometry::in(0, 2));
  }
};

struct LightSpec {
  Eigen::Vector3d direction{-0.4, 0.3, -1.0};  // world frame, the way the light travels
  double ambient = 0.45;
  double diffuse = 0.65;
  SunSpec sun{};       // when enabled, it sets the direction
  bool shadows = false;  // what the light does not reach keeps the ambient light only (shadow maps)
  int shadow_map = 2048;  // px a side of the shadow map, over the team's views at one instant
  double haze_visibility = 0;  // m of meteorological visibility (render/haze.hpp); 0: clear air
  CloudSpec clouds{};
  SkylightSpec skylight{};

  template <class V>
  void visit(V& v) {
    v("direction", direction);
    v.check("direction", direction.norm() >= 1e-9, "must not be the zero vector");
    v("ambient", ambient, geometry::in(0, 2));
    v("diffuse", diffuse, geometry::in(0, 2));
    v.section("sun", [&](auto& x) { sun.visit(x); });
    v.check("sun", !sun.enabled || travel().z() < 0, "the sun is below the horizon at that place and time");
    v("shadows", shadows);
    v("shadow_map", shadow_map, geometry::in(256, 8192));
    v("haze_visibility", haze_visibility, geometry::ge(0));
    v.section("clouds", [&](auto& x) { clouds.visit(x); });
    v.check("clouds", clouds.cover == 0 || shadows, "cloud shadows need shadows: true");
    v.section("skylight", [&](auto& x) { skylight.visit(x); });
  }
  // The way the light travels: the sun's when it is enabled, else `direction`; unit length.
  Eigen::Vector3d travel() const;
};

struct ImageEffectsSpec {
  int msaa = 1;                   // samples per pixel (1 = off; docs/rendering.md, image quality)
  double noise_sigma = 0;         // grey levels (0-255) of Gaussian sensor noise
  double blur_sigma = 0;          // px of Gaussian blur
  double exposure_gain = 1;       // multiplies the image
  double exposure_variation = 0;  // relative, per frame: gain * (1 + N(0, variation))
  Eigen::Vector3d sky{0.62, 0.74, 0.88};  // colour where no surface is hit

  template <class V>
  void visit(V& v) {
    v("msaa", msaa, geometry::in(1, 16));
    v.check("msaa", (msaa & (msaa - 1)) == 0, "must be 1, 2, 4, 8 or 16");
    v("noise_sigma", noise_sigma, geometry::ge(0));
    v("blur_sigma", blur_sigma, geometry::ge(0));
    v("exposure_gain", exposure_gain, geometry::gt(0));
    v("exposure_variation", exposure_variation, geometry::in(0, 1));
    v("sky", sky, geometry::in(0, 1));  // RGB
  }
};

// The team's own bodies (render/scene.hpp body_meshes): each UAV's model at its true position and
// yaw, seen by the other UAVs' cameras and casting its shadow (its own camera's included) when
// world.light.shadows is on. Off by default: the paper's cameras see no other UAV.
struct UavBodiesSpec {
  bool enabled = false;
  std::string model = "models/quadrotor/quadrotor.obj";  // scenario dir, then assets/
  double height = 0.28;   // m, the model is scaled to this height
  std::string up = "z";   // the model's up axis: y (glTF) or z
  double above = 0.05;    // m from the camera (the UAV's position) up to the model's bottom

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("model", model);
    v("height", height, geometry::in(0.01, 10));
    v.choice("up", up, {{"y", std::string("y")}, {"z", std::string("z")}});
    v("above", above, geometry::in(0, 10));
  }
};

struct WorldSpec {
  TerrainSpec terrain{};
  TextureSpec texture{};
  ObjectsSpec objects{};
  LeadModelSpec lead{};
  UavBodiesSpec uav_bodies{};
  LightSpec light{};
  ImageEffectsSpec image{};
  double near = 0.1, far = 1000;  // m, clip planes
  // What the relief, the objects and the procedural textures are drawn from. Fixed by default, so
  // that every run seed of a study flies over the same world (and, with a seed-free truth and no
  // per-frame image effects, sees the same frames, which a frame cache then renders once);
  // per_run draws a new world from each run's seed.
  geometry::SeedSetting seed{};

  template <class V>
  void visit(V& v) {
    v("seed", seed);
    v.section("terrain", [&](auto& x) { terrain.visit(x); });
    v.section("texture", [&](auto& x) { texture.visit(x); });
    v.section("objects", [&](auto& x) { objects.visit(x); });
    v.section("lead", [&](auto& x) { lead.visit(x); });
    v.section("uav_bodies", [&](auto& x) { uav_bodies.visit(x); });
    v.section("light", [&](auto& x) { light.visit(x); });
    v.section("image", [&](auto& x) { image.visit(x); });
    v("near", near, geometry::gt(0));
    v("far", far, geometry::gt(0));
    v.check("far", far > near, "must exceed near");
  }
};

// Terrain heights: seeded smooth relief around the mean height; with a ground lead, a flat road
// under its path at the lead's true height minus its reference height (its wheels never float or
// sink, docs/design.md, frames and conventions), and the land around it that road's height plus the relief.
class TerrainModel {
 public:
  TerrainModel(const Scenario& scn, const OpenLoopTruth& truth);
  double height(double x, double y) const;
  Eigen::Vector3d normal(double x, double y) const;
  // Square [xmin, ymin, xmax, ymax] the mesh covers.
  const Eigen::Vector4d& bounds() const { return bounds_; }
  // Horizontal distance to the lead's path.
  double distance_to_path(double x, double y, double* path_ground = nullptr) const;

 private:
  double relief(double x, double y) const;
  TerrainSpec spec_;
  bool follow_ = false;
  Eigen::Vector4d bounds_;
  struct Wave { double kx, ky, phase, amp; };
  std::vector<Wave> waves_;
  std::vector<Eigen::Vector3d> path_;  // (x, y, ground height) samples of the lead's path
};

struct WorldObject {
  enum class Type { Boulder, Tree, Building };
  Type type = Type::Boulder;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // base centre on the ground
  Eigen::Vector3d size = Eigen::Vector3d::Ones();      // m: length, width, height
  double yaw = 0;
  Eigen::Vector3d colour{0.5, 0.5, 0.5};
  std::uint32_t seed = 0;  // shape detail
};

// Objects over the terrain, reproducible from the world seed (WorldSpec::seed), clear of the lead's path.
std::vector<WorldObject> scatter_objects(const Scenario& scn, const TerrainModel& terrain);

// The roof cue floats this far above the model's top, so it never fights with the roof for depth.
inline constexpr double kLeadCueLift = 0.01;
// Height of the lead's reference point (the centre of its roof cue) above its ground contact:
// the model's height plus kLeadCueLift.
double lead_reference_height(const WorldSpec& w);

// Everything the renderer draws, resolved from a scenario: the world's spec, its terrain and the
// objects placed on it (along the open-loop flight), where relative asset paths start, and the
// seed of the procedural textures. render/ receives this, never the scenario or its truth.
struct WorldDescription {
  WorldSpec spec;
  TerrainModel terrain;
  std::vector<WorldObject> objects;
  std::string scenario_path;  // relative asset paths start next to it
  std::uint64_t seed = 1;
};
WorldDescription describe_world(const Scenario& scn);

// The lead's reference point and heading about world z at t: the model faces its direction of
// travel (the heading of t + 0.1 s at a standstill), turned by the world's yaw_offset.
struct LeadPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double yaw = 0;
};
LeadPose lead_pose(const Truth& truth, double t, const WorldSpec& world);
// Where each UAV's body is at t (world.uav_bodies): its true position and yaw; none when off.
std::vector<LeadPose> uav_body_poses(const Truth& truth, double t, const WorldSpec& world);
// The lead's heading about world z at t: its direction of travel (that of t + 0.1 s at a standstill).
double lead_heading(const Truth& truth, double t);

}  // namespace wingman::sim
