// A scene whose ground is one large image placed over its flight shows no repeat and no seam: every
// camera's footprint, in every frame, lies inside one copy of the image (the corners of each image
// cast onto the terrain).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "sim/assets.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"
#include "sim/world.hpp"

namespace wingman::sim {
namespace {

class GroundCover : public ::testing::TestWithParam<const char*> {};

TEST_P(GroundCover, EveryViewLiesInsideOneCopyOfTheMosaic) {
  const Scenario scn = load_scenarios(std::string(WINGMAN_SOURCE_DIR "/scenes/") + GetParam()).front();
  const TextureSpec& tex = scn.world.texture;
  const cv::Mat img = cv::imread(resolve_asset(tex.image, scn.source_path, "ground texture"));
  ASSERT_FALSE(img.empty());
  const double w = tex.tile_size, h = tex.tile_size * img.rows / img.cols;
  const OpenLoopTruth truth(scn);
  const TerrainModel terrain(scn, truth);
  double margin = 1e9;  // m, the least distance from a footprint corner to the copy's edge
  for (int k = 0; k <= scn.num_steps(); ++k) {
    const double t = k * scn.dt();
    for (int u = 0; u < static_cast<int>(scn.uavs.size()); ++u) {
      const geometry::PinholeCamera cam = scn.uavs[u].camera.camera();
      const Eigen::Matrix3d R_WC = truth.camera_R_CW(u, t).transpose();
      const Eigen::Vector3d c = truth.camera(u, t).position;
      for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(cam.width() - 1, 0),
                                           Eigen::Vector2d(0, cam.height() - 1),
                                           Eigen::Vector2d(cam.width() - 1, cam.height() - 1)}) {
        const Eigen::Vector3d ray = R_WC * cam.bearing(corner);
        Eigen::Vector3d p = c + ray * (c.z() / -ray.z());
        for (int it = 0; it < 3; ++it) p = c + ray * ((c.z() - terrain.height(p.x(), p.y())) / -ray.z());
        margin = std::min({margin, p.x() - tex.origin_x, tex.origin_x + w - p.x(), tex.origin_y - p.y(),
                           p.y() - (tex.origin_y - h)});
      }
    }
  }
  EXPECT_GT(margin, 0) << "a view reaches " << -margin << " m past the mosaic's edge";
}

// The park (Brighton Beach) and the construction site (Caliterra).
INSTANTIATE_TEST_SUITE_P(MosaicScenes, GroundCover,
                         ::testing::Values("person_park_rendered.yaml", "person_site_rendered.yaml"),
                         [](const ::testing::TestParamInfo<const char*>& i) {
                           return i.index == 0 ? std::string("Park") : std::string("ConstructionSite");
                         });

}  // namespace
}  // namespace wingman::sim
