#include "eval/stats/run_set.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "eval/output/json_file.hpp"

namespace wingman::eval {

RunSet::RunSet() : parsed_(std::make_shared<Parsed>()) {}

RunSet::RunSet(std::vector<std::filesystem::path> dirs) : dirs_(std::move(dirs)) {
  auto p = std::make_shared<Parsed>();
  p->metrics.reserve(dirs_.size());
  for (const auto& d : dirs_) p->metrics.push_back(read_json_file(d / "metrics.json"));
  parsed_ = std::move(p);
}

RunSet RunSet::slice(std::size_t first, std::size_t count) const {
  if (first + count > dirs_.size())
    throw std::out_of_range(fmt::format("RunSet::slice: runs {}..{} of {}", first, first + count, dirs_.size()));
  RunSet s;
  s.dirs_.assign(dirs_.begin() + static_cast<std::ptrdiff_t>(first),
                 dirs_.begin() + static_cast<std::ptrdiff_t>(first + count));
  s.parsed_ = parsed_;
  s.offset_ = offset_ + first;
  return s;
}

}  // namespace wingman::eval
