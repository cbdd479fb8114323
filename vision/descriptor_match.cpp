#include "vision/descriptor_match.hpp"

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace wingman::vision {

void DescriptorMatchSettings::validate() const {
  if (!(ratio > 0 && ratio <= 1))
    throw std::invalid_argument("descriptor match ratio must be in (0, 1], got " + std::to_string(ratio));
}

std::vector<cv::DMatch> match_descriptors(const Features& a, const Features& b,
                                          const DescriptorMatchSettings& s) {
  s.validate();
  if (a.size() == 0 || b.size() == 0) return {};
  if (a.norm != b.norm || a.descriptors.type() != b.descriptors.type())
    throw std::invalid_argument("match_descriptors: the two images have different descriptor types");
  cv::BFMatcher matcher(a.norm);
  std::vector<std::vector<cv::DMatch>> ab, ba;
  matcher.knnMatch(a.descriptors, b.descriptors, ab, 2);
  if (s.mutual) matcher.knnMatch(b.descriptors, a.descriptors, ba, 1);
  std::vector<cv::DMatch> out;
  for (const auto& m : ab) {
    if (m.empty()) continue;
    if (m.size() > 1 && !(m[0].distance < s.ratio * m[1].distance)) continue;
    if (s.mutual) {
      const auto& back = ba[static_cast<std::size_t>(m[0].trainIdx)];
      if (back.empty() || back[0].trainIdx != m[0].queryIdx) continue;
    }
    out.push_back(m[0]);
  }
  std::sort(out.begin(), out.end(), [](const cv::DMatch& x, const cv::DMatch& y) { return x.distance < y.distance; });
  return out;
}

}  // namespace wingman::vision
