#include "core/accel/tlas/instance_ids.h"

#include <algorithm>
#include <stdexcept>

#include "core/util/one_line.h"

namespace accelviz {

namespace {

bool parse_u32(std::string_view s, std::uint32_t& out) {
  if (s.empty() || s.size() > 10) return false;
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<std::uint64_t>(c - '0');
  }
  if (v > 0xFFFFFFFFull) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}

/// Digits only, but more than an id holds: said as such, not as bad syntax.
bool too_large(std::string_view s) {
  std::uint32_t v = 0;
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }) && !parse_u32(s, v);
}

struct IdRange {
  std::uint32_t lo = 0, hi = 0;
  bool all = false;
  std::string text;
};

/// The items of an id list, checked for syntax only.
std::vector<IdRange> parse_id_ranges(std::string_view text) {
  // Spaces may stand beside a comma ("0, 2"); a comma without an item on
  // each side is a typo, reported rather than skipped.
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != ',') continue;
    std::size_t before = i, after = i + 1;
    while (before > 0 && text[before - 1] == ' ') --before;
    while (after < text.size() && text[after] == ' ') ++after;
    if (before == 0 || text[before - 1] == ',' || after == text.size() || text[after] == ',')
      throw std::invalid_argument("instances: an empty item in '" + first_line(std::string(text)) +
                                  "' (expected e.g. 0,2,5-9 or all)");
  }
  std::vector<IdRange> out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find_first_of(", ", pos);
    const std::string_view item = text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
    pos = end == std::string_view::npos ? text.size() : end + 1;
    if (item.empty()) continue;
    IdRange r;
    r.text = std::string(item);
    const std::size_t dash = item.find('-');
    if (item == "all") {
      r.all = true;
    } else if (too_large(item.substr(0, dash)) ||
               (dash != std::string_view::npos && too_large(item.substr(dash + 1)))) {
      throw std::invalid_argument("instances: '" + r.text + "' has an id beyond 4294967295, the largest there can be");
    } else if (dash == std::string_view::npos) {
      if (!parse_u32(item, r.lo))
        throw std::invalid_argument("instances: '" + r.text + "' is not an instance id (expected e.g. 0,2,5-9 or all)");
      r.hi = r.lo;
    } else if (!parse_u32(item.substr(0, dash), r.lo) || !parse_u32(item.substr(dash + 1), r.hi) || r.hi < r.lo) {
      throw std::invalid_argument("instances: '" + r.text + "' is not a range LO-HI with LO <= HI");
    }
    out.push_back(std::move(r));
  }
  if (out.empty()) throw std::invalid_argument("instances: none given (expected e.g. 0,2,5-9 or all)");
  return out;
}

}  // namespace

void check_instance_ids(std::string_view text) {
  parse_id_ranges(text);
}

std::vector<std::uint32_t> parse_instance_ids(std::string_view text, std::size_t count) {
  std::vector<std::uint32_t> ids;
  for (const IdRange& r : parse_id_ranges(text)) {
    if (r.all) {
      for (std::size_t i = 0; i < count; ++i) ids.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    if (r.hi >= count)
      throw std::invalid_argument("instances: '" + r.text + "' is out of range (the scene has " +
                                  count_of(count, "instance") + ")");
    for (std::uint64_t i = r.lo; i <= r.hi; ++i) ids.push_back(static_cast<std::uint32_t>(i));
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

std::string format_instance_ids(const std::vector<std::uint32_t>& ids) {
  std::string out;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(ids[i]);
    if (j > i) {
      out += j == i + 1 ? ',' : '-';
      out += std::to_string(ids[j]);
    }
    i = j + 1;
  }
  return out;
}

}  // namespace accelviz
