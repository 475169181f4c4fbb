#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/spec.h"

#include "core/scene/scene.h"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <system_error>

namespace accelviz::procedural {

void spec_error(std::string_view name, const std::string& problem) {
  // A name is echoed back; keep a pathological one from flooding the line.
  std::string shown(name.substr(0, 40));
  if (name.size() > 40) shown += "...";
  throw SceneError("builtin:" + shown + ": " + problem);
}

namespace {

// Values are echoed in messages; keep a hostile spec from making them long or
// multi-line.
std::string quoted(std::string_view text) {
  std::string out = "'";
  for (char c : text.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (text.size() > 40) out += "...";
  return out + "'";
}

std::string key_list(std::span<const RealParam> extra) {
  std::string keys = "size, seed";
  for (const RealParam& p : extra) keys += ", " + std::string(p.key);
  return keys;
}

std::string number(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

}  // namespace

bool parse_int64(std::string_view text, std::int64_t& out) {
  if (text.empty()) return false;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, out);
  if (ec == std::errc() && ptr == end) return true;
  // Accept integral scientific forms such as "1e6" or "2.5e5"; std::from_chars
  // is locale-independent, unlike strtod.
  double d = 0.0;
  auto [dptr, dec] = std::from_chars(text.data(), end, d, std::chars_format::general);
  if (dec != std::errc() || dptr != end || !std::isfinite(d) || d != std::floor(d)) return false;
  if (d >= 9.2e18) {
    out = INT64_MAX;
  } else if (d <= -9.2e18) {
    out = INT64_MIN;
  } else {
    out = static_cast<std::int64_t>(d);
  }
  return true;
}

bool parse_uint64(std::string_view text, std::uint64_t& out) {
  if (text.empty() || text.front() < '0' || text.front() > '9') return false;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && ptr == end;
}

bool parse_real(std::string_view text, double& out) {
  if (text.empty()) return false;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, out, std::chars_format::general);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}

SpecParts split_spec(std::string_view spec) {
  constexpr std::string_view kPrefix = "builtin:";
  if (spec.substr(0, kPrefix.size()) == kPrefix) spec.remove_prefix(kPrefix.size());
  SpecParts parts;
  const std::size_t q = spec.find('?');
  parts.name = std::string(spec.substr(0, q));
  if (parts.name.empty()) spec_error("", "missing scene name (expected builtin:NAME?key=value&...)");
  for (char c : parts.name)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'))
      spec_error(quoted(parts.name), "scene names use only a-z, 0-9 and '-'");
  if (q == std::string_view::npos) return parts;
  std::string_view query = spec.substr(q + 1);
  if (query.empty()) spec_error(parts.name, "empty parameter list after '?'");
  while (true) {
    const std::size_t amp = query.find('&');
    const std::string_view item = query.substr(0, amp);
    const std::size_t eq = item.find('=');
    if (item.empty()) spec_error(parts.name, "empty parameter (two '&' in a row or a trailing '&')");
    if (eq == std::string_view::npos) spec_error(parts.name, "parameter " + quoted(item) + " is not key=value");
    const std::string key(item.substr(0, eq));
    const std::string value(item.substr(eq + 1));
    if (key.empty()) spec_error(parts.name, "parameter " + quoted(item) + " has an empty key");
    if (value.empty()) spec_error(parts.name, "key " + quoted(key) + " has an empty value");
    for (const auto& [k, v] : parts.items)
      if (k == key) spec_error(parts.name, "key " + quoted(key) + " given twice");
    parts.items.emplace_back(key, value);
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return parts;
}

BuiltinArgs resolve_args(const SpecParts& parts, std::string source, std::int64_t default_size,
                         std::span<const RealParam> extra) {
  BuiltinArgs args;
  args.source = std::move(source);
  args.name = parts.name;
  args.size = default_size;
  for (const RealParam& p : extra) args.reals.emplace_back(std::string(p.key), p.default_value);

  for (const auto& [key, value] : parts.items) {
    if (key == "size") {
      std::int64_t size = 0;
      if (!parse_int64(value, size))
        spec_error(parts.name, "size=" + quoted(value) + " is not a whole number of triangles (1.." +
                                   std::to_string(kMaxBuiltinSize) + ")");
      if (size <= 0) spec_error(parts.name, "size=" + quoted(value) + " must be at least 1");
      if (size > kMaxBuiltinSize)
        spec_error(parts.name, "size=" + quoted(value) + " is too large: at most " +
                                   std::to_string(kMaxBuiltinSize) + " triangles");
      args.size = size;
      continue;
    }
    if (key == "seed") {
      if (!parse_uint64(value, args.seed))
        spec_error(parts.name, "seed=" + quoted(value) + " is not an unsigned 64-bit decimal integer");
      continue;
    }
    bool known = false;
    for (std::size_t i = 0; i < extra.size(); ++i) {
      if (key != extra[i].key) continue;
      known = true;
      double v = 0.0;
      if (!parse_real(value, v) || v < extra[i].min || v > extra[i].max)
        spec_error(parts.name, key + "=" + quoted(value) + " is not a number in [" + number(extra[i].min) + ", " +
                                   number(extra[i].max) + "]");
      if (extra[i].whole && v != std::floor(v))
        spec_error(parts.name, key + "=" + quoted(value) + " is not a whole number in [" + number(extra[i].min) + ", " +
                                   number(extra[i].max) + "]");
      args.reals[i].second = v;
    }
    if (!known) spec_error(parts.name, "unknown key " + quoted(key) + "; valid keys: " + key_list(extra));
  }
  return args;
}

double BuiltinArgs::real(std::string_view key) const {
  for (const auto& [k, v] : reals)
    if (k == key) return v;
  throw std::logic_error("builtin:" + name + ": generator reads undeclared key " + std::string(key));
}

}  // namespace accelviz::procedural
