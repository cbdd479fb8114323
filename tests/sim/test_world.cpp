// The `world:` section: defaults when absent, strict parsing with file:line:key errors, and the
// terrain model (flat road under a ground lead that follows its height, seeded relief, objects
// clear of the path).
#include <gtest/gtest.h>

#include <tuple>

#include "sim/assets.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"
#include "sim/world.hpp"

namespace wingman::sim {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_scenarios(yaml, "w.yaml");
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "no error";
}

TEST(World, DefaultsWhenAbsent) {
  const Scenario s = parse_scenarios("name: x\n", "w.yaml").front();
  EXPECT_EQ(s.world.texture.type, TextureSpec::Type::Image);
  EXPECT_EQ(s.world.lead.cue, LeadModelSpec::Cue::Aruco);
  EXPECT_EQ(s.world.image.msaa, 1);
  EXPECT_EQ(s.world.texture.anisotropy, 1.0);
  EXPECT_EQ(s.world.texture.filter, TextureSpec::Filter::Trilinear);
  EXPECT_NE(s.world.lead.model.find("CesiumMilkTruck"), std::string::npos);
}

TEST(World, ParsesEverySection) {
  const Scenario s = parse_scenarios(R"(name: x
world:
  terrain: {extent: 300, mean_height: 1, relief: 0.5, relief_scale: 30, resolution: 4}
  texture: {type: procedural, detail_min: 0.03, detail_max: 0.15, size: 512, anisotropy: 8,
            filter: bilinear}
  objects: {boulders: 5, trees: 0, buildings: 1, clearance: 10}
  lead: {model: my/truck.obj, kind: aerial, height: 1.5, up: z, cue: panel, panel_colour: [0, 1, 1]}
  light: {direction: [0, 0, -1], ambient: 0.3, diffuse: 0.8}
  image: {msaa: 8, noise_sigma: 2, blur_sigma: 0.5, exposure_gain: 1.1, exposure_variation: 0.05}
  near: 0.5
  far: 500
)", "w.yaml").front();
  const WorldSpec& w = s.world;
  EXPECT_EQ(w.terrain.extent, 300);
  EXPECT_EQ(w.terrain.resolution, 4);
  EXPECT_EQ(w.texture.type, TextureSpec::Type::Procedural);
  EXPECT_EQ(w.texture.size, 512);
  EXPECT_EQ(w.texture.filter, TextureSpec::Filter::Bilinear);
  EXPECT_EQ(w.objects.trees, 0);
  EXPECT_EQ(w.lead.model, "my/truck.obj");
  EXPECT_EQ(w.lead.kind, LeadModelSpec::Kind::Aerial);
  EXPECT_EQ(w.lead.up, "z");
  EXPECT_EQ(w.lead.cue, LeadModelSpec::Cue::Panel);
  EXPECT_EQ(w.lead.panel_colour, Eigen::Vector3d(0, 1, 1));
  EXPECT_EQ(w.image.msaa, 8);
  EXPECT_EQ(w.image.noise_sigma, 2);
  EXPECT_EQ(w.far, 500);
}

TEST(World, ErrorsNameFileLineAndKey) {
  EXPECT_EQ(error_of("world:\n  terrain: {relif: 1}\n"),
            "w.yaml:2:13: world.terrain.relif: unknown key 'relif' (did you mean 'relief'?)");
  EXPECT_NE(error_of("world:\n  texture: {mode: mirrored}\n")
                .find("w.yaml:2:19: world.texture.mode: expected one of tiled, stretched, got 'mirrored'"),
            std::string::npos);
  EXPECT_NE(error_of("world:\n  texture: {filter: nearest}\n")
                .find("w.yaml:2:21: world.texture.filter: expected one of trilinear, bilinear, got 'nearest'"),
            std::string::npos);
  EXPECT_NE(error_of("world:\n  image: {msaa: 3}\n").find("world.image.msaa: must be 1, 2, 4, 8 or 16"),
            std::string::npos);
  EXPECT_NE(error_of("world:\n  texture: {detail_min: 0.5, detail_max: 0.1}\n")
                .find("world.texture.detail_max"),
            std::string::npos);
  EXPECT_NE(error_of("world:\n  near: 10\n  far: 5\n").find("w.yaml:3:8: world.far"), std::string::npos);
  EXPECT_NE(error_of("world:\n  lead: {aruco_id: 50}\n").find("world.lead.aruco_id: must be in [0, 49]"),
            std::string::npos);
}

// A file the world names that rendering would read is checked when a rendered scenario is loaded
// (and by check_world_files before `wingman render` draws a synthetic one), naming line and key.
TEST(World, MissingFilesOfARenderedWorldAreErrorsAtTheirKey) {
  const std::string model = "measurements: rendered\nworld:\n  lead: {model: models/nope.glb}\n";
  const std::string err = error_of(model);
  EXPECT_EQ(err.rfind("w.yaml:3:17: world.lead.model: 'models/nope.glb': file not found (looked at ", 0), 0u)
      << err;
  EXPECT_NE(err.find(assets_dir() + "/models/nope.glb"), std::string::npos) << err;
  EXPECT_EQ(error_of("measurements: rendered\nworld:\n  texture:\n    image: no/such.png\n")
                .rfind("w.yaml:4:12: world.texture.image: 'no/such.png': file not found", 0),
            0u);
  // A procedural texture reads no image; the shipped defaults exist.
  EXPECT_EQ(error_of("measurements: rendered\nworld:\n  texture: {type: procedural, image: no.png}\n"),
            "no error");
  EXPECT_EQ(error_of("measurements: rendered\n"), "no error");

  // Synthetic measurements render nothing: the scenario loads, and the check names the same place.
  const Scenario s = parse_scenarios("world:\n  lead: {model: models/nope.glb}\n", "w.yaml").front();
  try {
    check_world_files(s);
    FAIL() << "no error";
  } catch (const ScenarioError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("w.yaml:2:17: world.lead.model: 'models/nope.glb'", 0), 0u) << e.what();
  }
  Scenario d = parse_scenarios("name: x\n", "w.yaml").front();
  d.world.texture.image = "gone.jpg";
  try {
    check_world_files(d);
    FAIL() << "no error";
  } catch (const ScenarioError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("w.yaml: world.texture.image (default): 'gone.jpg'", 0), 0u) << e.what();
  }
}

TEST(World, FindAssetLooksNextToTheScenarioThenInAssets) {
  const auto a = find_asset("aerial/freetown_drone_nadir.jpg", "/no/such/dir/s.yaml");
  ASSERT_TRUE(a.path.has_value());
  EXPECT_EQ(*a.path, assets_dir() + "/aerial/freetown_drone_nadir.jpg");
  const std::string here = std::string(WINGMAN_SOURCE_DIR) + "/scenes/paper_rendered.yaml";
  EXPECT_EQ(find_asset("rendered_smoke.yaml", here).path.value_or(""),
            std::string(WINGMAN_SOURCE_DIR) + "/scenes/rendered_smoke.yaml");
  EXPECT_EQ(find_asset(here, "").path.value_or(""), here);  // absolute: as it is
  const auto miss = find_asset("x.png", "/d/s.yaml");
  EXPECT_FALSE(miss.path.has_value());
  EXPECT_EQ(miss.looked_text(), "/d/x.png, " + assets_dir() + "/x.png");
}

TEST(World, TerrainFollowsAGroundLeadAndIsSeeded) {
  Scenario s = parse_scenarios("name: x\nduration: 60\n", "w.yaml").front();
  const OpenLoopTruth truth(s);
  const TerrainModel terrain(s, truth);
  for (double t : {0.0, 13.3, 42.0}) {
    const Eigen::Vector3d p = truth.lead(t).position;
    EXPECT_NEAR(terrain.height(p.x(), p.y()), p.z() - lead_reference_height(s.world), 0.02) << t;
  }
  // A zero-length run (one frame) still has its road.
  Scenario one = s;
  one.duration = 0;
  const TerrainModel terrain0(one, truth);
  EXPECT_NEAR(terrain0.height(0, 0), -lead_reference_height(s.world), 1e-9);
  // Away from the path: the relief of the world's seed, within its amplitude.
  Scenario other = s;
  other.world.seed.value = s.world.seed.value + 1;
  const TerrainModel terrain2(other, truth);
  const Eigen::Vector4d& b = terrain.bounds();
  const double x = b(0) + 5, y = b(1) + 5;
  double road = 0;
  ASSERT_GT(terrain.distance_to_path(x, y, &road), s.world.terrain.road_half_width + s.world.terrain.road_blend);
  EXPECT_LE(std::abs(terrain.height(x, y) - road), s.world.terrain.relief + 1e-9);
  EXPECT_NE(terrain.height(x, y), terrain2.height(x, y));
  // Objects are reproducible and keep clear of the path.
  const auto a = scatter_objects(s, terrain), a2 = scatter_objects(s, terrain);
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), a2.size());
  EXPECT_EQ(a.front().position, a2.front().position);
  for (const auto& o : a)
    EXPECT_GT(terrain.distance_to_path(o.position.x(), o.position.y()), s.world.objects.clearance);
}

TEST(World, SeedIsFixedByDefaultAndTheRunsOnlyWhenPerRun) {
  Scenario s = parse_scenarios("name: x\nduration: 30\n", "w.yaml").front();
  EXPECT_EQ(s.world.seed, (geometry::SeedSetting{false, 1}));
  const auto relief_and_objects = [](const Scenario& scn) {
    const WorldDescription w = describe_world(scn);
    const Eigen::Vector4d& b = w.terrain.bounds();
    return std::make_tuple(w.terrain.height(b(0) + 5, b(1) + 5), w.objects.front().position, w.seed);
  };
  Scenario seed7 = s;
  seed7.seed = 7;
  EXPECT_EQ(relief_and_objects(s), relief_and_objects(seed7));  // another run seed, the same world
  Scenario per_run = parse_scenarios("name: x\nduration: 30\nworld: {seed: per_run}\n", "w.yaml").front();
  EXPECT_TRUE(per_run.world.seed.per_run);
  EXPECT_EQ(relief_and_objects(per_run), relief_and_objects(s));  // per_run with run seed 1: world 1
  per_run.seed = 7;
  EXPECT_NE(std::get<0>(relief_and_objects(per_run)), std::get<0>(relief_and_objects(s)));
  EXPECT_EQ(std::get<2>(relief_and_objects(per_run)), 7u);  // and the procedural textures' seed
  Scenario world7 = parse_scenarios("name: x\nduration: 30\nworld: {seed: 7}\n", "w.yaml").front();
  EXPECT_EQ(relief_and_objects(world7), relief_and_objects(per_run));

  EXPECT_NE(error_of("world:\n  seed: each\n").find("w.yaml:2:9: world.seed: expected an integer or per_run, got 'each'"),
            std::string::npos) << error_of("world:\n  seed: each\n");
  EXPECT_NE(error_of("world:\n  seed: -3\n").find("world.seed: must be >= 0"), std::string::npos);
}

}  // namespace
}  // namespace wingman::sim
