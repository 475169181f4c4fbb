#pragma once
// Brute force: test every primitive. The reference every structure is
// checked against, and the baseline its speed-up is quoted over.
#include "core/accel/accel.h"
#include "core/math/aabb.h"

#include <span>
#include <vector>

namespace accelviz {

struct BruteForceOptions {
  bool bbox_early_out = false;  ///< test each primitive's box before the triangle
};

class BruteForce final : public Accelerator {
 public:
  BruteForce(std::span<const Triangle> triangles, const BruteForceOptions& opts = {});

  std::string name() const override { return opts_.bbox_early_out ? "brute-bbox" : "brute"; }
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  const BuildStats& build_stats() const override { return stats_; }

 private:
  std::span<const Triangle> tris_;
  std::vector<Aabb> boxes_;
  BruteForceOptions opts_;
  BuildStats stats_;
};

}  // namespace accelviz
