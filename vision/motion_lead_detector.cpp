#include "vision/motion_lead_detector.hpp"

#include <algorithm>
#include <array>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>
#include <string>

namespace wingman::vision {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("motion lead detector: " + what);
}

cv::Point2d apply(const cv::Mat& H, const cv::Point2d& p) {
  const double* h = H.ptr<double>();
  const double w = h[6] * p.x + h[7] * p.y + h[8];
  return {(h[0] * p.x + h[1] * p.y + h[2]) / w, (h[3] * p.x + h[4] * p.y + h[5]) / w};
}

// The median of an 8-bit image over `valid`, from its histogram.
double masked_median(const cv::Mat& img, const cv::Mat& valid) {
  std::array<int, 256> hist{};
  int n = 0;
  for (int r = 0; r < img.rows; ++r) {
    const uchar* p = img.ptr<uchar>(r);
    const uchar* m = valid.ptr<uchar>(r);
    for (int c = 0; c < img.cols; ++c)
      if (m[c]) ++hist[p[c]], ++n;
  }
  int seen = 0;
  for (int v = 0; v < 256; ++v)
    if ((seen += hist[v]) * 2 >= n) return v;
  return 0;
}

// Pixels that are the ground darkened: darker than the background, with its texture (normalised
// cross-correlation over 7 x 7 above 0.6 where the background has texture). A lead's shadow moves
// with it and differs from the background as much as the lead does; its texture is the ground's.
cv::Mat shadow(const cv::Mat& grey, const cv::Mat& bg) {
  cv::Mat a, b;
  grey.convertTo(a, CV_32F), bg.convertTo(b, CV_32F);
  const cv::Size win(7, 7);
  cv::Mat ma, mb, maa, mbb, mab;
  cv::boxFilter(a, ma, CV_32F, win), cv::boxFilter(b, mb, CV_32F, win);
  cv::boxFilter(a.mul(a), maa, CV_32F, win), cv::boxFilter(b.mul(b), mbb, CV_32F, win);
  cv::boxFilter(a.mul(b), mab, CV_32F, win);
  const cv::Mat va = maa - ma.mul(ma), vb = mbb - mb.mul(mb), cov = mab - ma.mul(mb);
  cv::Mat den;
  cv::sqrt(cv::max(va.mul(vb), 1e-6), den);
  const cv::Mat ncc = cov / den;
  // Where neither has texture, a uniform darkening (to 0.3-0.85 of the background) is taken for
  // a shadow too: a lead's dark, uniform parts are then lost, its bright ones kept.
  const cv::Mat darker = (a < 0.9 * b);
  const cv::Mat textured = (ncc > 0.6) & (vb > 16.0);
  const cv::Mat flat = (va < 16.0) & (vb < 16.0) & (a < 0.85 * b) & (a > 0.3 * b);
  return darker & (textured | flat);
}

}  // namespace

void MotionLeadSettings::validate() const {
  require(downscale >= 1 && downscale <= 8, "downscale must be in [1, 8], got " + std::to_string(downscale));
  require(step_px > 0, "step_px must be > 0, got " + std::to_string(step_px));
  require(references >= 3 && references <= 15, "references must be in [3, 15], got " + std::to_string(references));
  require(history >= references, "history must be >= references, got " + std::to_string(history));
  require(threshold > 0 && threshold < 255, "threshold must be in (0, 255), got " + std::to_string(threshold));
  require(min_area_px > 0, "min_area_px must be > 0, got " + std::to_string(min_area_px));
  require(window_half_px >= 8, "window_half_px must be >= 8, got " + std::to_string(window_half_px));
}

MotionLeadDetector::MotionLeadDetector(const MotionLeadSettings& settings) : cfg_(settings) { cfg_.validate(); }

bool MotionLeadDetector::track_ground(const cv::Mat& grey, cv::Mat& H) const {
  std::vector<cv::Point2f> from, to;
  cv::goodFeaturesToTrack(previous_, from, 300, 0.001, 8);
  if (from.size() < 12) return false;
  std::vector<uchar> ok;
  std::vector<float> err;
  // Started where the last step's motion puts each corner: the team's speed changes slowly.
  cv::perspectiveTransform(from, to, last_step_);
  cv::calcOpticalFlowPyrLK(previous_, grey, from, to, ok, err, cv::Size(21, 21), 4,
                           cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01),
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < from.size(); ++i)
    if (ok[i]) a.push_back(from[i]), b.push_back(to[i]);
  if (a.size() < 12) return false;
  std::vector<uchar> inlier;
  H = cv::findHomography(a, b, cv::RANSAC, 1.5, inlier);
  // The ground is most of the image: a fit that explains few of the tracks is not the ground's.
  return !H.empty() && cv::countNonZero(inlier) >= std::max<int>(12, static_cast<int>(a.size()) / 3);
}

std::vector<int> MotionLeadDetector::references(const cv::Point2d& at) const {
  std::vector<int> refs;
  const double step = cfg_.step_px / cfg_.downscale;
  for (int i = 0; i < static_cast<int>(earlier_.size()) && static_cast<int>(refs.size()) < cfg_.references; ++i) {
    // Where the ground now at `at` was in that frame: H^-1 maps the current frame back.
    const cv::Point2d back = apply(earlier_[i].to_current.inv(), at);
    if (std::hypot(back.x - at.x, back.y - at.y) >= step * static_cast<double>(refs.size() + 1)) refs.push_back(i);
  }
  // Fewer would leave a pixel that the lead crossed in half of them or more.
  if (static_cast<int>(refs.size()) < cfg_.references) refs.clear();
  return refs;
}

cv::Mat MotionLeadDetector::background(const std::vector<int>& refs, cv::Mat& valid) const {
  const cv::Size size = previous_.size();
  std::vector<cv::Mat> warped, inside;
  const cv::Mat ones(earlier_.front().grey.size(), CV_8U, cv::Scalar(255));
  for (int i : refs) {
    cv::Mat w, m;
    cv::warpPerspective(earlier_[i].grey, w, earlier_[i].to_current, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::warpPerspective(ones, m, earlier_[i].to_current, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
    warped.push_back(w), inside.push_back(m);
  }
  // The median of the references that cover each pixel; a pixel most of them miss is not judged.
  cv::Mat bg(size, CV_8U, cv::Scalar(0));
  valid = cv::Mat(size, CV_8U, cv::Scalar(0));
  std::vector<uchar> v(refs.size());
  for (int r = 0; r < size.height; ++r)
    for (int c = 0; c < size.width; ++c) {
      std::size_t n = 0;
      for (std::size_t k = 0; k < refs.size(); ++k)
        if (inside[k].at<uchar>(r, c)) v[n++] = warped[k].at<uchar>(r, c);
      if (n * 2 <= refs.size()) continue;
      std::nth_element(v.begin(), v.begin() + n / 2, v.begin() + n);
      bg.at<uchar>(r, c) = v[n / 2];
      valid.at<uchar>(r, c) = 255;
    }
  return bg;
}

std::optional<LeadDetection> MotionLeadDetector::blob(const std::optional<Eigen::Vector2d>& predicted) const {
  // Parts less than about 25 px apart (a rotor and the next, a body and its arm) are one blob;
  // its centroid and area are its moving pixels'.
  cv::Mat grouped, labels;
  cv::dilate(mask_, grouped, cv::getStructuringElement(cv::MORPH_ELLIPSE, {25 / cfg_.downscale | 1, 25 / cfg_.downscale | 1}));
  const int n = cv::connectedComponents(grouped, labels, 8, CV_32S);
  std::vector<Eigen::Vector3d> sums(static_cast<std::size_t>(n), Eigen::Vector3d::Zero());  // x, y, count
  for (int r = 0; r < mask_.rows; ++r) {
    const uchar* m = mask_.ptr<uchar>(r);
    const int* l = labels.ptr<int>(r);
    for (int c = 0; c < mask_.cols; ++c)
      if (m[c]) sums[static_cast<std::size_t>(l[c])] += Eigen::Vector3d(c, r, 1);
  }
  const double s = cfg_.downscale, min_area = cfg_.min_area_px / (s * s);
  int best = -1;
  double best_key = 0;
  for (int i = 1; i < n; ++i) {
    const double area = sums[i].z();
    if (area < min_area) continue;
    const Eigen::Vector2d uv = s * sums[i].head<2>() / area + Eigen::Vector2d::Constant(0.5 * (s - 1));
    // Nearest the prediction within the window, else the largest.
    const double key = predicted ? -(uv - *predicted).norm() : area;
    if (predicted && -key > cfg_.window_half_px) continue;
    if (best < 0 || key > best_key) best = i, best_key = key;
  }
  if (best < 0) return std::nullopt;
  LeadDetection d;
  const double area = sums[best].z();
  d.uv = s * sums[best].head<2>() / area + Eigen::Vector2d::Constant(0.5 * (s - 1));
  d.size_px = s * std::sqrt(area);
  d.confidence = std::min(1.0, area / (4 * min_area));
  d.source = LeadSource::Motion;
  return d;
}

std::optional<LeadDetection> MotionLeadDetector::detect(const cv::Mat& image,
                                                        const std::optional<Eigen::Vector2d>& predicted) {
  cv::Mat grey = lead_search_grey(image, "MotionLeadDetector::detect");
  if (cfg_.downscale > 1) cv::resize(grey, grey, grey.size() / cfg_.downscale, 0, 0, cv::INTER_AREA);
  mask_ = cv::Mat(grey.size(), CV_8U, cv::Scalar(0));
  cv::Mat H;
  const bool tracked = !previous_.empty() && previous_.size() == grey.size() && track_ground(grey, H);
  if (!tracked) {
    earlier_.clear();  // a new sequence, or a ground that could not be followed: start again
    last_step_ = cv::Mat::eye(3, 3, CV_64F);
  } else {
    last_step_ = H;
    earlier_.push_front({previous_, cv::Mat::eye(3, 3, CV_64F)});
    for (auto& e : earlier_) e.to_current = H * e.to_current;
    if (static_cast<int>(earlier_.size()) > cfg_.history) earlier_.pop_back();
  }
  previous_ = grey.clone();
  const double s = cfg_.downscale;
  const cv::Point2d at = predicted ? cv::Point2d((predicted->x() - 0.5 * (s - 1)) / s, (predicted->y() - 0.5 * (s - 1)) / s)
                                   : cv::Point2d(0.5 * (grey.cols - 1), 0.5 * (grey.rows - 1));
  const std::vector<int> refs = references(at);
  if (refs.empty()) return std::nullopt;
  cv::Mat valid;
  const cv::Mat bg = background(refs, valid);
  cv::Mat diff;
  cv::absdiff(grey, bg, diff);
  diff.setTo(0, valid == 0);
  const double tau = std::max(cfg_.threshold, 4 * masked_median(diff, valid));
  mask_ = (diff >= tau) & ~shadow(grey, bg);
  // Close the lead's uniform patches into one blob, then drop specks of noise and aliasing.
  cv::morphologyEx(mask_, mask_, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
  cv::morphologyEx(mask_, mask_, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {9, 9}));
  return blob(predicted);
}

}  // namespace wingman::vision
