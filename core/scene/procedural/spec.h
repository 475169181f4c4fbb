#pragma once
// Parsing and validation of built-in scene specs:
//   builtin:NAME?key=value&key=value      ("builtin:" optional)
// Keys every scene takes: size (approximate triangle count) and seed
// (unsigned 64-bit, default 1). Scenes may declare further numeric keys.
// Every problem throws SceneError("builtin:NAME: <problem>"), one line.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace accelviz::procedural {

/// Largest accepted `size`: caps the allocation a spec can ask for
/// (200 M triangles are about 7 GB of world-space triangles).
inline constexpr std::int64_t kMaxBuiltinSize = 200'000'000;
inline constexpr std::uint64_t kDefaultSeed = 1;

/// A scene-specific numeric key, validated to [min, max].
struct RealParam {
  std::string_view key;
  double default_value;
  double min;
  double max;
  std::string_view help;  ///< one line, for builtin_scenes()
  bool whole = false;     ///< a count: only whole numbers are accepted
};

/// A spec cut into its name and its key=value items (in spec order, unvalidated).
struct SpecParts {
  std::string name;
  std::vector<std::pair<std::string, std::string>> items;
};

/// Splits SPEC. Throws on an empty name, an item without '=', an empty key or
/// value, or a repeated key.
SpecParts split_spec(std::string_view spec);

/// The validated arguments a generator receives.
struct BuiltinArgs {
  std::string source;  ///< the spec as given, with the "builtin:" prefix ensured
  std::string name;
  std::int64_t size = 0;
  std::uint64_t seed = kDefaultSeed;
  std::vector<std::pair<std::string, double>> reals;  ///< every declared extra key, defaulted

  /// Value of a declared extra key (throws std::logic_error for an undeclared one:
  /// a programming error, not a user error).
  double real(std::string_view key) const;
};

/// Checks PARTS against the keys size, seed and EXTRA; fills defaults.
BuiltinArgs resolve_args(const SpecParts& parts, std::string source, std::int64_t default_size,
                         std::span<const RealParam> extra);

/// Throws SceneError("builtin:NAME: PROBLEM").
[[noreturn]] void spec_error(std::string_view name, const std::string& problem);

// Value parsers (exposed for the tests). Each returns false on malformed text.
bool parse_int64(std::string_view text, std::int64_t& out);   ///< decimal, or an integral "1e6" form
bool parse_uint64(std::string_view text, std::uint64_t& out);  ///< decimal only, full 64-bit range
bool parse_real(std::string_view text, double& out);           ///< finite decimal or scientific

}  // namespace accelviz::procedural
