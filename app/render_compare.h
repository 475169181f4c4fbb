#pragma once
// accelviz render --compare: the same view rendered with two configurations
// (A: the command's own options; B: A with the --compare overrides), written
// as three PNGs: A and B on one locked colour scale, and B - A on a
// diverging colour map, with the totals of both printed.
#include <string>

#include "app/cli_common.h"
#include "core/analysis/heatmap.h"

namespace accelviz::cli {

/// One side of a comparison: structure, its options and the query options.
struct CompareSide {
  std::string structure = "bvh";
  StructureCli structure_opts;
  std::string triangle_test = "watertight";
  std::string order = "front-to-back";  ///< front-to-back, back-to-front, unordered
  bool xray = false;
};

/// "" or why `side`'s traversal order cannot be honoured by its structure:
/// bvh and tlas take every --order and --xray; kdtree and octree
/// front-to-back and unordered; the others have no child order (a grid steps
/// its cells along the ray). Without this the option was ignored in silence
/// (and the caption named it).
std::string order_problem(const CompareSide& side);

/// `spec` is "key=value key=value ..." (spaces or commas between pairs) over
/// a copy of `a`. Keys: structure, splitter, buckets, leaf, leaf-cap, ctrav,
/// cisect, embree-quality, triangle-test, order, xray (0/1). Throws
/// UsageError "--compare: ..." naming the bad key or value.
CompareSide parse_compare_spec(const std::string& spec, const CompareSide& a);

/// The three output paths for `out` = DIR/NAME.png: DIR/NAME-a.png, -b.png, -diff.png.
struct ComparePaths {
  std::string a, b, diff;
};
ComparePaths compare_paths(const std::string& out);

/// A side's options as the JSON names them: the structure and every option
/// that can differ between the sides and applies to it (triangle_test but
/// for Embree; splitter, buckets (binned), leaf, leaf_cap, xray for bvh and
/// tlas; order for those and kdtree, octree; ctrav, cisect for bvh, tlas and
/// the cost metric; embree_quality, embree_robust for Embree), and
/// per_ray_counters is added once the side is built (Accelerator::inspectable()).
nlohmann::json describe_side(const CompareSide& side, HeatMetric metric);

/// QueryOptions of a side (order, x-ray, triangle test).
QueryOptions query_of(const CompareSide& side);

/// The heatmap options of a side: `metric` on a `size` image traced on
/// `threads`, with the side's query options and cost weights (--ctrav,
/// --cisect). What `render` traces its one side with, and each side of --compare.
HeatmapOptions heatmap_options_of(const CompareSide& side, HeatMetric metric, const ImageSize& size, unsigned threads);

struct CompareJob {
  std::string scene;
  std::string camera;
  std::string size = "800x600";
  std::string metric = "nodes";
  std::string colormap = "viridis";
  std::string legend = "bottom";
  float max = 0.0f;
  unsigned threads = 0;
  std::string out;
  bool force = false;
  CompareSide a, b;
  double max_percentile = 0.0;  ///< > 0: the shared top at this percentile of both images' values
};

/// Runs the comparison: prints the three paths, then one JSON line with both
/// sides' figures and totals. Returns the exit code.
int run_render_compare(const CompareJob& job, const GlobalOptions& global);

}  // namespace accelviz::cli
