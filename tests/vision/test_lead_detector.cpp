// Lead detector: an ArUco marker rendered (anti-aliased, exactly known centre) into an aerial image
// is found within 1 px, also under strong perspective and at 20 px with a prediction; nothing is
// returned without it; the colour-panel fallback finds a magenta disc.
#include <gtest/gtest.h>

#include <opencv2/aruco.hpp>

#include "vision/lead_detector.hpp"
#include "vision_test_support.hpp"

using namespace wingman::vision;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

cv::Mat background() {
  return test::PlaneScene().render(test::view_at({0, 0, 15}));  // 640 x 480 aerial view
}

// Draws the marker whose black square is [-0.5, 0.5]^2 in marker coordinates, with a one-cell
// white quiet zone, through the homography H (marker coordinates -> pixels), 8 x 8 supersampled.
void draw_marker(cv::Mat& img, const Eigen::Matrix3d& H, int id = 0, int dict = cv::aruco::DICT_4X4_50) {
  const auto d = cv::aruco::getPredefinedDictionary(dict);
  const int cells = d->markerSize + 2;
  cv::Mat bits;
  cv::aruco::drawMarker(d, id, cells, bits, 1);  // one pixel per cell
  const double q = 0.5 + 1.0 / cells;            // quiet zone half-size
  const Eigen::Matrix3d Hi = H.inverse();
  double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
  for (double sx : {-q, q})
    for (double sy : {-q, q}) {
      const Vector3d p = H * Vector3d(sx, sy, 1);
      umin = std::min(umin, p.x() / p.z()), umax = std::max(umax, p.x() / p.z());
      vmin = std::min(vmin, p.y() / p.z()), vmax = std::max(vmax, p.y() / p.z());
    }
  constexpr int ss = 8;
  for (int y = int(vmin) - 1; y <= int(vmax) + 1; ++y)
    for (int x = int(umin) - 1; x <= int(umax) + 1; ++x) {
      cv::Vec3d acc(0, 0, 0);
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const Vector3d m = Hi * Vector3d(x - 0.5 + (i + 0.5) / ss, y - 0.5 + (j + 0.5) / ss, 1);
          const double X = m.x() / m.z(), Y = m.y() / m.z();
          if (std::abs(X) > q || std::abs(Y) > q) {
            acc += cv::Vec3d(img.at<cv::Vec3b>(y, x));
          } else if (std::abs(X) >= 0.5 || std::abs(Y) >= 0.5) {
            acc += cv::Vec3d(255, 255, 255);
          } else {
            const int c = std::clamp(int((X + 0.5) * cells), 0, cells - 1);
            const int r = std::clamp(int((Y + 0.5) * cells), 0, cells - 1);
            const double g = bits.at<uchar>(r, c);
            acc += cv::Vec3d(g, g, g);
          }
        }
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(acc / double(ss * ss));
    }
}

Eigen::Matrix3d similarity(Vector2d centre, double side, double angle) {
  Eigen::Matrix3d H;
  H << side * std::cos(angle), -side * std::sin(angle), centre.x(), side * std::sin(angle),
      side * std::cos(angle), centre.y(), 0, 0, 1;
  return H;
}

}  // namespace

TEST(LeadDetector, FindsA30PxMarkerWithin1Px) {
  for (double angle : {0.0, 0.4, 1.3, 2.9}) {
    cv::Mat img = background();
    const Vector2d centre(412.3, 187.7);
    draw_marker(img, similarity(centre, 30, angle));
    const auto d = LeadDetector().detect(img);
    ASSERT_TRUE(d) << "angle " << angle;
    EXPECT_LT((d->uv - centre).norm(), 1.0) << "angle " << angle << ": " << d->uv.transpose();
    EXPECT_EQ(d->source, LeadSource::Marker);
    EXPECT_NEAR(d->size_px, 30, 2);
    EXPECT_DOUBLE_EQ(d->confidence, 1.0);
    // A prediction far off: the neighbourhood passes find nothing, the whole frame does.
    const auto far = LeadDetector().detect(img, Vector2d(50, 400));
    ASSERT_TRUE(far);
    EXPECT_LT((far->uv - d->uv).norm(), 1e-6);
    // A good prediction searches its neighbourhood and agrees with the whole-frame result.
    const auto near = LeadDetector().detect(img, centre + Vector2d(5, 5));
    ASSERT_TRUE(near);
    EXPECT_LT((near->uv - centre).norm(), 1.0);
  }
}

TEST(LeadDetector, DiagonalIntersectionIsTheCentreUnderPerspective) {
  cv::Mat img = background();
  const Vector2d centre(250.6, 300.2);
  Eigen::Matrix3d P;
  P << 1, 0, 0, 0, 1, 0, 0.35, 0.2, 1;  // strong keystone
  draw_marker(img, similarity(centre, 34, 0.3) * P);
  const auto d = LeadDetector().detect(img);
  ASSERT_TRUE(d);
  const Vector2d mean = 0.25 * (d->corners[0] + d->corners[1] + d->corners[2] + d->corners[3]);
  EXPECT_LT((d->uv - centre).norm(), 1.0) << d->uv.transpose();
  EXPECT_GT((mean - centre).norm(), (d->uv - centre).norm());  // the corner mean is biased
}

TEST(LeadDetector, ReturnsNothingWithoutTheMarkerOrWithAnotherId) {
  const cv::Mat img = background();
  EXPECT_FALSE(LeadDetector().detect(img));
  EXPECT_FALSE(LeadDetector().detect(img, Vector2d(320, 240)));
  cv::Mat other = background();
  draw_marker(other, similarity({300, 200}, 30, 0.2), 7);
  EXPECT_FALSE(LeadDetector().detect(other));
  LeadDetectorSettings s;
  s.marker_id = 7;
  ASSERT_TRUE(LeadDetector(s).detect(other));
}

TEST(LeadDetector, SmallMarkerWithAPredictionIsFoundInTheUpscaledRegion) {
  cv::Mat img = background();
  const Vector2d centre(150.4, 350.9);
  draw_marker(img, similarity(centre, 18, 0.5));
  const auto d = LeadDetector().detect(img, centre + Vector2d(9, -6));
  ASSERT_TRUE(d);
  EXPECT_LT((d->uv - centre).norm(), 1.0) << d->uv.transpose();
}

// The window-only search reads the window alone: the same detection as detect() when the marker
// is in it, nothing when only the whole-image pass would find it; the pixels outside the window
// do not matter.
TEST(LeadDetector, TheWindowSearchReadsOnlyItsWindow) {
  cv::Mat img = background();
  const Vector2d centre(150.4, 350.9);
  draw_marker(img, similarity(centre, 30, 0.3));
  LeadDetector finder;
  const Vector2d near = centre + Vector2d(20, -15), far(400, 100);
  const auto window = finder.window(img.size(), near);
  ASSERT_TRUE(window);
  EXPECT_EQ(window->width, 2 * finder.settings().roi_half_px + 1);
  cv::Mat only = cv::Mat::zeros(img.size(), img.type());
  img(*window).copyTo(only(*window));
  const auto whole = finder.detect(img, near), in_window = finder.detect_in_window(only, near);
  ASSERT_TRUE(whole && in_window);
  EXPECT_EQ(whole->uv, in_window->uv);
  EXPECT_TRUE(finder.detect(img, far));             // found by the whole-image pass
  EXPECT_FALSE(finder.detect_in_window(img, far));  // not in the window around the prediction
  LeadDetectorSettings colour;
  colour.method = LeadMethod::Colour;
  EXPECT_FALSE(LeadDetector(colour).window(img.size(), near));  // a panel is searched over the image
}

TEST(LeadDetector, ColourFallbackFindsTheMagentaPanelCentroid) {
  cv::Mat img = background();
  LeadDetectorSettings s;
  s.method = LeadMethod::Colour;
  EXPECT_FALSE(LeadDetector(s).detect(img));  // the ground has no such colour
  const Vector2d centre(333.25, 120.75);
  cv::circle(img, cv::Point(cvRound(centre.x() * 16), cvRound(centre.y() * 16)), 9 * 16, cv::Scalar(255, 0, 255),
             cv::FILLED, cv::LINE_AA, 4);
  const auto d = LeadDetector(s).detect(img);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->source, LeadSource::Colour);
  EXPECT_LT((d->uv - centre).norm(), 0.5) << d->uv.transpose();
  EXPECT_GT(d->confidence, 0.3);
  s.method = LeadMethod::MarkerThenColour;  // no marker: the panel
  ASSERT_TRUE(LeadDetector(s).detect(img));
  s.method = LeadMethod::Marker;
  EXPECT_FALSE(LeadDetector(s).detect(img));
}

TEST(LeadDetector, ParsesNamesAndRejectsBadSettingsByName) {
  EXPECT_EQ(parse_lead_method("marker"), LeadMethod::Marker);
  EXPECT_EQ(parse_lead_method("colour"), LeadMethod::Colour);
  EXPECT_EQ(parse_lead_method("marker_then_colour"), LeadMethod::MarkerThenColour);
  EXPECT_EQ(parse_aruco_dictionary("DICT_4X4_50"), cv::aruco::DICT_4X4_50);
  EXPECT_EQ(parse_aruco_dictionary("DICT_APRILTAG_36h11"), cv::aruco::DICT_APRILTAG_36h11);
  auto message = [](auto f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message([] { parse_aruco_dictionary("DICT_9X9"); }).find("DICT_9X9"), std::string::npos);
  EXPECT_NE(message([] { parse_lead_method("radar"); }).find("radar"), std::string::npos);
  LeadDetectorSettings s;
  s.marker_id = 50;
  EXPECT_NE(message([&] { LeadDetector{s}; }).find("50"), std::string::npos);
  const auto box = exclusion_box(LeadDetection{{100, 100}, 1, LeadSource::Marker, {}, 30}, 1.5, 20);
  EXPECT_TRUE(box.contains({140, 60}));
  EXPECT_FALSE(box.contains({150, 100}));
}
