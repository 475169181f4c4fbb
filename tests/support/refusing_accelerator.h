#pragma once
// A structure whose queries throw for every ray, as Embree's do for rays beyond its reach (a scene
// of half-size 1e13, say): for tests of the callers that must say so rather than end the program.
#include <stdexcept>
#include <string>

#include "core/accel/accel.h"

namespace accelviz::testing {

class RefusingAccelerator final : public Accelerator {
 public:
  std::string name() const override { return "refusing"; }
  Hit closest_hit(const Ray&, const QueryOptions&, RayStats*, VisitTrace*) const override {
    throw std::invalid_argument("refusing: cannot trace this ray");
  }
  bool any_hit(const Ray&, const QueryOptions&, RayStats*) const override {
    throw std::invalid_argument("refusing: cannot trace this ray");
  }
  const BuildStats& build_stats() const override { return stats_; }
  std::string ray_problem(const Ray&) const override { return "cannot trace this ray"; }

 private:
  BuildStats stats_;
};

}  // namespace accelviz::testing
