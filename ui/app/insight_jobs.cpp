#include "ui/app/insight_jobs.h"

#include <cstdio>

#include "core/accel/bvh/bvh.h"
#include "core/accel/factory.h"
#include "core/query/ray_sets.h"

namespace accelviz {

namespace {
ProgressCallback stopper(const std::atomic<bool>& cancel) {
  return [&cancel](double) { return !cancel.load(); };
}
}  // namespace

std::string describe_choice(const StructureChoice& c) {
  std::string s = c.name;
  if (c.name == "bvh") {
    const BvhOptions& b = c.options.bvh;
    s += std::string(" ") + to_string(b.splitter);
    if (b.splitter == BvhSplitter::binned_sah) s += " B=" + std::to_string(b.buckets);
    s += " leaf " + std::to_string(b.max_leaf_size);
  }
  if (!c.query.ordered)
    s += ", unordered";
  else if (c.query.back_to_front)
    s += ", back-to-front";
  if (c.query.xray) s += ", x-ray";
  return s;
}

ABResult run_ab(const ABRequest& r, const std::atomic<bool>& cancel) {
  if (!r.scene) throw std::invalid_argument("A/B: no scene shown yet");
  ABResult out;
  out.a = r.a;
  out.b = r.b;
  const StructureChoice* side[2] = {&r.a, &r.b};
  MetricImage* img[2] = {&out.image_a, &out.image_b};
  const std::vector<Ray> primary = primary_rays(r.camera, r.width, r.height);
  std::vector<Hit> hits[2];
  for (int s = 0; s < 2; ++s) {
    StructureOptions so = side[s]->options;
    so.threads = r.threads;
    so.bvh.compute_epo = false;
    const auto accel = build_accelerator(side[s]->name, r.scene->scene.triangles, so, stopper(cancel));
    (s == 0 ? out.build_ms_a : out.build_ms_b) = accel->build_stats().build_ms;
    (s == 0 ? out.sah_a : out.sah_b) = accel->build_stats().sah_cost;
    if (!accel->inspectable()) out.uncounted = accel->name();
    // The cost metric with each side's own SAH costs, as render --compare.
    const HeatmapOptions ho{.metric = r.metric,
                            .width = r.width,
                            .height = r.height,
                            .threads = r.threads,
                            .query = side[s]->query,
                            .c_trav = so.bvh.cost_traversal,
                            .c_isect = so.bvh.cost_intersect,
                            .progress = stopper(cancel)};
    *img[s] = render_metric(*accel, r.camera, ho);
    // What the choice costs in time and what it changes, as render --compare.
    TimedClosestHits timed = time_closest_hits(*accel, primary, side[s]->query, r.threads, 3, stopper(cancel));
    (s == 0 ? out.trace_ms_a : out.trace_ms_b) = timed.trace_ms;
    (s == 0 ? out.hits_a : out.hits_b) = timed.hit_count;
    hits[s] = std::move(timed.hits);
  }
  out.hits_changed = hits_changed(hits[0], hits[1]);
  out.diff = difference_image(out.image_a, out.image_b, &out.figures);
  out.locked_max = locked_scale_max(out.image_a, out.image_b, 0.0f);
  out.diff_scale = out.figures.max_abs_diff > 0.0 ? static_cast<float>(out.figures.max_abs_diff) : 1.0f;
  return out;
}

ViewInsight run_view_insight(const ViewInsightRequest& r, const std::atomic<bool>& cancel) {
  if (!r.built) throw std::invalid_argument("insight: no structure shown yet");
  ViewInsight v;
  v.built = r.built;
  const Accelerator& accel = *r.built->accel;
  v.record = record_view_visits(accel, r.camera, r.width, r.height, r.built->choice.query, r.threads, stopper(cancel));
  v.visits = node_visit_counts(v.record, r.built->nodes.size());
  v.hot = top_hot_nodes(v.visits, 20);
  if (const auto* bvh = dynamic_cast<const Bvh*>(&accel)) {
    v.is_bvh = true;
    v.cost = compare_predicted_measured(*bvh, v.record);
    v.predicted = bvh_hit_probabilities(bvh->nodes());
    v.measured = measured_entry_fractions(v.record, bvh->nodes().size());
  }
  const std::vector<Ray> rays = primary_rays(r.camera, r.width, r.height);
  for (const TraversalMode m : kTraversalModes) {
    if (cancel.load()) throw BuildCancelled();
    v.modes.push_back(measure_mode(accel, rays, r.built->choice.query, m, r.threads));
  }
  return v;
}

}  // namespace accelviz
