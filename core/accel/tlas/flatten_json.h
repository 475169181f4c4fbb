#pragma once
// JSON of the flatten what-if's figures, one form for `accelviz flatten
// --json` and the GUI's dump-flatten. Header-only: core itself writes no JSON
// here; its users link nlohmann/json.
#include <nlohmann/json.hpp>

#include "core/accel/tlas/flatten_what_if.h"

namespace accelviz {

inline void to_json(nlohmann::json& j, const TwoLevelFigures& f) {
  j = {{"sah_cost", f.sah_cost},
       {"memory_bytes", f.memory_bytes},
       {"build_ms", f.build_ms},
       {"instances", f.instances},
       {"blas", f.blas},
       {"rays", f.rays},
       {"hits", f.hits},
       {"mean_nodes", f.mean_nodes},
       {"mean_prims", f.mean_prims},
       {"mean_instances", f.mean_instances},
       {"trace_ms", f.trace_ms}};
}

/// merged_instances, merged_triangles and the two_level / flattened figures.
inline nlohmann::json flatten_what_if_json(const FlattenWhatIf& w) {
  return {{"merged_instances", w.merged_instances},
          {"merged_triangles", w.merged_triangles},
          {"two_level", w.two_level},
          {"flattened", w.flattened}};
}

}  // namespace accelviz
