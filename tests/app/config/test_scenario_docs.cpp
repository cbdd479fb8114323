// docs/scenario.md and the code cannot drift apart: the schema blocks of the page (the scenario,
// its frontend: and control: sections) are read as YAML and compared, key by key, with the
// resolved configuration of a scenario that sets nothing.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app/config/run_config.hpp"

namespace wingman::app {
namespace {

// The ```yaml blocks of the page before its prose on what the settings mean, merged into one map.
YAML::Node documented_schema() {
  std::ifstream in(WINGMAN_SOURCE_DIR "/docs/scenario.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string page = ss.str();
  const std::string schema = page.substr(0, page.find("## What the estimator settings mean"));
  YAML::Node merged(YAML::NodeType::Map);
  // Found with string searches: std::regex recurses once per character of a block, which a long
  // page (or a sanitizer's larger frames) turns into a stack overflow.
  const std::string open = "```yaml\n", close = "```";
  for (std::size_t at = schema.find(open); at != std::string::npos; at = schema.find(open, at)) {
    const std::size_t body = at + open.size(), end = schema.find(close, body);
    if (end == std::string::npos) break;
    for (const auto& kv : YAML::Load(schema.substr(body, end - body))) merged[kv.first.Scalar()] = kv.second;
    at = end + close.size();
  }
  return merged;
}

bool same_scalar(const std::string& a, const std::string& b) {
  if (a == b) return true;
  char* end_a = nullptr;
  char* end_b = nullptr;
  const double x = std::strtod(a.c_str(), &end_a), y = std::strtod(b.c_str(), &end_b);
  return *end_a == '\0' && *end_b == '\0' && !a.empty() && !b.empty() &&
         std::abs(x - y) <= 1e-12 * std::max(1.0, std::abs(x));
}

// Keys whose documented value is an example, not the default.
const std::set<std::string> kExamples = {"name", "phases", "outages", "variants", "control.disturbance.seed"};

// Keys whose default is `auto`: the resolved configuration prints the value derived for the
// scenario (app/config/derived_noise.hpp), the page says `auto`.
const std::set<std::string> kDerived = {
    "estimator.process_noise.accel_sigma_lead", "estimator.process_noise.accel_sigma_uav",
    "estimator.process_noise.accel_sigma_common", "estimator.measurement_noise.pixel_sigma",
    "estimator.measurement_noise.pixel_offset_sigma"};

// Every key of `code` is documented with its value; with `subset`, only the documented keys are
// compared (list entries after the first are examples of the same shape).
void compare(const YAML::Node& doc, const YAML::Node& code, const std::string& path, bool subset,
             std::vector<std::string>& problems) {
  if (kExamples.count(path)) return;
  if (kDerived.count(path)) {
    if (!doc.IsScalar() || doc.Scalar() != "auto") problems.push_back(path + ": its default is auto");
    return;
  }
  if (code.IsMap()) {
    if (!doc.IsMap()) return problems.push_back(path + ": documented as something other than a map");
    for (const auto& kv : code) {
      const std::string key = kv.first.Scalar(), sub = path.empty() ? key : path + "." + key;
      if (!doc[key]) {
        if (!subset && !kExamples.count(sub)) problems.push_back(sub + ": not documented");
        continue;
      }
      compare(doc[key], kv.second, sub, subset, problems);
    }
    for (const auto& kv : doc) {
      const std::string key = kv.first.Scalar();
      if (!code[key] && !kExamples.count(path.empty() ? key : path + "." + key)) problems.push_back((path.empty() ? key : path + "." + key) + ": documented, not in the code");
    }
  } else if (code.IsSequence()) {
    if (!doc.IsSequence() || (doc.size() != code.size() && !subset))
      return problems.push_back(path + ": documented with another number of entries");
    for (std::size_t i = 0; i < std::min(doc.size(), code.size()); ++i)
      compare(doc[i], code[i], path + "[" + std::to_string(i) + "]", subset || (i > 0 && code[i].IsMap()),
              problems);
  } else if (!doc.IsScalar() || !same_scalar(doc.Scalar(), code.Scalar())) {
    problems.push_back(path + ": documented " + (doc.IsScalar() ? doc.Scalar() : std::string("a non-scalar")) +
                       ", the default is " + code.Scalar());
  }
}

TEST(ScenarioDocs, SchemaBlockMatchesTheDefaultConfiguration) {
  // control: {} for the closed loop's defaults; nothing else is set.
  const RunConfig defaults = parse_run_configs("control: {}\n", "defaults.yaml").front();
  const YAML::Node code = YAML::Load(config_yaml(defaults));
  std::vector<std::string> problems;
  compare(documented_schema(), code, "", false, problems);
  for (const auto& p : problems) ADD_FAILURE() << "docs/scenario.md: " << p;
  EXPECT_GT(code["estimator"]["gating"].size(), 3u);  // the walk reached the module sections
}

// The comparison itself catches a drift: a default changed in code but not in the page.
TEST(ScenarioDocs, ComparisonNamesAKeyWhoseDefaultDiffers) {
  RunConfig defaults = parse_run_configs("control: {}\n", "defaults.yaml").front();
  defaults.estimator.measurement_noise.orientation_sigma = 0;
  std::vector<std::string> problems;
  compare(documented_schema(), YAML::Load(config_yaml(defaults)), "", false, problems);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0], "estimator.measurement_noise.orientation_sigma: documented 0.028, the default is 0");
}

}  // namespace
}  // namespace wingman::app
