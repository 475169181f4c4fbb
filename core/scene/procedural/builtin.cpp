// The registry of built-in scenes: make_builtin() and builtin_scenes() from
// core/scene/load.h. Each entry names its generator, its default size, what
// size means for it, and its scene-specific keys; the list is the single
// source for validation, --help and docs/builtin-scenes.md.
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/load.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/spec.h"

#include <charconv>
#include <string>
#include <vector>

namespace accelviz {

namespace {

using procedural::BuiltinArgs;
using procedural::RealParam;

constexpr std::int64_t kDefaultSize = 100'000;

struct Entry {
  const char* name;
  const char* description;
  const char* size_meaning;  ///< what `size` controls, for the parameter line
  bool uses_seed;
  std::vector<RealParam> extra;
  Scene (*make)(const BuiltinArgs&);
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {"teapot",
       "the Utah teapot, Newell's 32 Bezier patches tessellated evenly",
       "triangles, >= 240; sets the patch grid n (64 n^2 - 8 n triangles)",
       false,
       {},
       procedural::make_teapot},
      {"teapot-stadium",
       "a dense teapot in a huge sparse stadium (the demo): tiny detail inside vast empty bounds",
       "total triangles; the stadium takes 834, the teapot the rest",
       false,
       {{"ratio", 1000.0, 10.0, 1e6, "stadium diameter / teapot size"}},
       procedural::make_teapot_stadium},
      {"grass",
       "a lawn of thin, overlapping grass blades on a ground square",
       "triangles; 3 per blade at 200 blades per unit^2",
       true,
       {},
       procedural::make_grass},
      {"terrain",
       "a height field of fBm value noise over x, z in [-50, 50]",
       "triangles; an n x n grid with 2 n^2 triangles",
       true,
       {},
       procedural::make_terrain},
      {"soup",
       "random triangles in the unit cube, size ~ N^(-1/3)",
       "triangles, exactly",
       true,
       {},
       procedural::make_soup},
      {"walls",
       "thin wall boxes of a k x k floor plan with doorways, axis-aligned",
       "triangles; 12 per wall box, 12 (k+1)(3k+1) in all",
       true,
       {{"angle", 0.0, -360.0, 360.0, "rotation of the plan about +y, degrees"}},
       procedural::make_walls},
      {"walls-rotated",
       "the same walls rotated 45 degrees about +y: loose boxes",
       "triangles; 12 per wall box, 12 (k+1)(3k+1) in all",
       true,
       {{"angle", 45.0, -360.0, 360.0, "rotation of the plan about +y, degrees"}},
       procedural::make_walls},
      {"forest",
       "one tree mesh instanced many times on a ground square",
       "instanced triangles; 96 per tree (plus 2 for the ground)",
       true,
       {},
       procedural::make_forest},
      {"island",
       "a Moana-like island: a height field and 8 plant species, each instanced `copies` times (left "
       "unflattened above 50M instanced triangles: tlas only)",
       "UNIQUE triangles, <= 10000000; about 0.1 size + 0.9 size copies instanced",
       true,
       {{"copies", 4.0, 1.0, 100000.0, "instances of each of the 8 plant species", /*whole=*/true}},
       procedural::make_island},
      {"dynamic",
       "thousands of animated boxes (glTF-style TRS channels: linear, step, cubic spline) over a lawn of "
       "waving grass (a deforming mesh)",
       "triangles; 12 per box for 3/4 of size, the lawn (3 per blade + 2) the rest",
       true,
       {},
       procedural::make_dynamic},
      {"same-centroid",
       "degenerate: N varied triangles sharing one centroid exactly",
       "triangles, exactly",
       true,
       {},
       procedural::make_same_centroid},
      {"same-bounds",
       "degenerate: N distinct triangles with identical bounding boxes",
       "triangles, exactly",
       true,
       {},
       procedural::make_same_bounds},
      {"duplicates",
       "degenerate: one triangle repeated N times",
       "triangles, exactly",
       true,
       {},
       procedural::make_duplicates},
      {"flat-wall",
       "degenerate: N random triangles all in the plane z = 0",
       "triangles, exactly",
       true,
       {},
       procedural::make_flat_wall},
  };
  return entries;
}

std::string format_number(double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string parameter_line(const Entry& e) {
  std::string line = "size (" + std::string(e.size_meaning) + "; default " + std::to_string(kDefaultSize) + ")";
  line += e.uses_seed ? ", seed (default 1)" : ", seed (accepted, no effect)";
  for (const RealParam& p : e.extra)
    line += ", " + std::string(p.key) + " (" + std::string(p.help) + "; default " + format_number(p.default_value) +
            ", " + format_number(p.min) + ".." + format_number(p.max) + ")";
  return line;
}

}  // namespace

const std::vector<BuiltinSceneInfo>& builtin_scenes() {
  static const std::vector<BuiltinSceneInfo> infos = [] {
    std::vector<BuiltinSceneInfo> out;
    for (const Entry& e : registry()) out.push_back({e.name, e.description, parameter_line(e)});
    return out;
  }();
  return infos;
}

Scene make_builtin(const std::string& spec) {
  const procedural::SpecParts parts = procedural::split_spec(spec);
  for (const Entry& e : registry()) {
    if (parts.name != e.name) continue;
    std::string source = spec.rfind("builtin:", 0) == 0 ? spec : "builtin:" + spec;
    const BuiltinArgs args = procedural::resolve_args(parts, std::move(source), kDefaultSize, e.extra);
    return e.make(args);
  }
  std::string names;
  for (const Entry& e : registry()) names += (names.empty() ? "" : ", ") + std::string(e.name);
  procedural::spec_error(parts.name, "unknown scene; valid names: " + names);
}

}  // namespace accelviz
