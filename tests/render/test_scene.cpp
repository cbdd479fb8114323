// The world built from a scenario: the paper's scene renders the same twice, the lead's
// reference point is the centre of its roof marker and it spans >= 30 px from 15 m, and bad
// asset paths are clear errors naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "render_test_support.hpp"
#include "sim/assets.hpp"
#include "sim/truth.hpp"

namespace wingman::render {
namespace {

namespace fs = std::filesystem;
using testing::backend_name;

const std::string kPaper = std::string(WINGMAN_SOURCE_DIR) + "/scenes/paper_synthetic.yaml";

sim::Scenario paper(int size = 200) {
  sim::Scenario s = sim::load_scenarios(kPaper).front();
  s.world.texture.anisotropy = 4;
  for (auto& u : s.uavs) {
    // Same field of view as the paper's camera, fewer pixels: fast on llvmpipe.
    const double k = size / 1000.0;
    u.camera.fx = u.camera.fy = 200.1 * k;
    u.camera.cx = u.camera.cy = 500 * k + 0.5 * k - 0.5;
    u.camera.width = u.camera.height = size;
  }
  return s;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("wingman-scene-test-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

TEST(Scene, LeadIsScaledToItsHeightAndSpansThirtyPixelsFromFifteenMetres) {
  const sim::Scenario scn = sim::load_scenarios(kPaper).front();
  const Scene s = build_scene(sim::describe_world(scn));
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const auto& m : s.lead_meshes)
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
      const Eigen::Vector3d p(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  EXPECT_NEAR(hi.z(), 0.0, 1e-6);  // the reference point is on top: the roof cue
  EXPECT_NEAR(hi.z() - lo.z(), scn.world.lead.height + sim::kLeadCueLift, 1e-3);
  const double span_px = 200.1 * (hi.x() - lo.x()) / 15.0;
  EXPECT_GE(span_px, 30.0);
}

// world.texture's filter between mipmap levels reaches every texture, the lead's included.
TEST(Scene, MaterialsTakeTheWorldsSamplingAndSolidsNoAnisotropy) {
  sim::Scenario scn = sim::load_scenarios(kPaper).front();
  scn.world.texture.anisotropy = 1;
  scn.world.texture.filter = sim::TextureSpec::Filter::Bilinear;
  const Scene s = build_scene(sim::describe_world(scn));
  ASSERT_GE(s.materials.size(), 4u);  // ground, objects, the truck's textures, the cue
  int lead_textured = 0;
  for (const auto& m : s.lead_meshes) lead_textured += m.material >= 0;
  EXPECT_GT(lead_textured, 0);
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    EXPECT_EQ(s.materials[i].anisotropy, 1.0) << "material " << i;
    EXPECT_FALSE(s.materials[i].trilinear) << "material " << i;
  }
  // Anisotropy reaches the ground and the flat cue; solids (objects, the model's own textures),
  // whose faces can be seen edge-on, sample without it (docs/studies/render-object-cost.md).
  scn.world.texture.anisotropy = 8;
  scn.world.texture.filter = sim::TextureSpec::Filter::Trilinear;
  const Scene aniso = build_scene(sim::describe_world(scn));
  for (std::size_t i = 0; i < aniso.materials.size(); ++i) {
    const Material& m = aniso.materials[i];
    const bool ground_or_cue = i == 0 || m.unlit;
    EXPECT_EQ(m.anisotropy, ground_or_cue ? 8.0 : 1.0) << "material " << i;
    EXPECT_TRUE(m.trilinear) << "material " << i;
  }
  EXPECT_TRUE(aniso.materials.back().unlit);  // the cue
}

TEST(Scene, MissingModelNonModelAndMissingTextureAreErrorsNamingTheFile) {
  TempDir tmp;
  sim::LeadModelSpec spec;
  Scene s;
  const std::string missing = (tmp.path / "no_such_truck.glb").string();
  try {
    load_lead_model(spec, missing, Material{}, s);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos) << e.what();
  }
  const std::string junk = (tmp.path / "junk.glb").string();
  std::ofstream(junk) << "this is not a 3D model\n";
  try {
    load_lead_model(spec, junk, Material{}, s);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(junk), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a 3D model"), std::string::npos) << e.what();
  }
  sim::Scenario scn = paper();
  scn.world.texture.image = "no_such_aerial.jpg";
  try {
    build_scene(sim::describe_world(scn));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_aerial.jpg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("scenes/no_such_aerial.jpg"), std::string::npos)
        << "should say where it looked: " << e.what();
  }
}

TEST(Scene, RelativeAssetsResolveNextToTheScenarioFirst) {
  TempDir tmp;
  std::ofstream(tmp.path / "tex.png") << "x";
  const std::string scn_file = (tmp.path / "s.yaml").string();
  EXPECT_EQ(sim::resolve_asset("tex.png", scn_file, "texture"), (tmp.path / "tex.png").string());
  EXPECT_NE(sim::resolve_asset("aerial/freetown_drone_nadir.jpg", scn_file, "texture").find("assets"),
            std::string::npos);
}

TEST(Scene, ProceduralTextureFollowsTheWorldSeed) {
  sim::Scenario a = paper();
  a.world.texture.type = sim::TextureSpec::Type::Procedural;
  a.world.texture.size = 256;
  sim::Scenario other_world = a, other_run = a;
  other_world.world.seed.value = a.world.seed.value + 1;
  other_run.seed = a.seed + 1;  // the world's seed is fixed: the same texture
  const Scene sa = build_scene(sim::describe_world(a)), sa2 = build_scene(sim::describe_world(a)),
              sb = build_scene(sim::describe_world(other_world)), sr = build_scene(sim::describe_world(other_run));
  EXPECT_EQ(cv::norm(sa.materials[0].texture, sa2.materials[0].texture, cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(sa.materials[0].texture, sb.materials[0].texture, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(sa.materials[0].texture, sr.materials[0].texture, cv::NORM_INF), 0);
}

class PaperSceneTest : public ::testing::TestWithParam<GlBackend> {};

TEST_P(PaperSceneTest, SameScenarioAndSeedGiveIdenticalImages) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const sim::Scenario scn = paper();
  const sim::OpenLoopTruth truth(scn);
  const double t = 12.3;
  const CameraView view{scn.uavs[0].camera.camera(), truth.camera_R_CW(0, t), truth.camera(0, t).position};
  Frame first, second;
  {
    Renderer r(ctx, build_scene(sim::describe_world(scn)));
    first = r.render(view, sim::lead_pose(truth, t, scn.world));
  }
  {
    Renderer r(ctx, build_scene(sim::describe_world(scn)));
    second = r.render(view, sim::lead_pose(truth, t, scn.world));
  }
  EXPECT_EQ(cv::norm(first.rgb, second.rgb, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(first.depth, second.depth, cv::NORM_INF), 0);
}

TEST_P(PaperSceneTest, LeadReferencePointIsWhereTheDepthSaysAndBothUavsSeeIt) {
  WINGMAN_REQUIRE_CONTEXT(GetParam(), ctx);
  const sim::Scenario scn = paper(400);
  const sim::OpenLoopTruth truth(scn);
  Renderer r(ctx, build_scene(sim::describe_world(scn)));
  for (double t : {0.0, 30.0}) {
    const LeadPose lead = sim::lead_pose(truth, t, scn.world);
    for (int j = 0; j < 2; ++j) {
      const CameraView view{scn.uavs[j].camera.camera(), truth.camera_R_CW(j, t),
                            truth.camera(j, t).position};
      const Frame f = r.render(view, lead);
      const Eigen::Vector3d p_C = view.pose.R_CW * (lead.position - view.pose.position);
      const auto uv = view.camera.project(p_C);
      ASSERT_TRUE(uv && view.camera.in_image(*uv, 20)) << "lead out of view of uav" << j + 1;
      const float d = f.depth.at<float>(static_cast<int>(std::lround(uv->y())),
                                        static_cast<int>(std::lround(uv->x())));
      EXPECT_NEAR(d, p_C.z(), 0.02) << "uav" << j + 1 << " t=" << t;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, PaperSceneTest,
                         ::testing::Values(GlBackend::Egl, GlBackend::OsMesa), backend_name);

}  // namespace
}  // namespace wingman::render
