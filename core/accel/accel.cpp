#include "core/accel/accel.h"

#include <stdexcept>

namespace accelviz {

void Accelerator::closest_hits(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts,
                               std::span<RayStats> stats) const {
  if (hits.size() != rays.size())
    throw std::invalid_argument("closest_hits: " + name() + ": the hit span differs in size from the ray span");
  if (!stats.empty() && stats.size() != rays.size())
    throw std::invalid_argument("closest_hits: " + name() + ": the stats span must be empty or match the ray span");
  closest_hits_span(rays, hits, opts, stats);
}

void Accelerator::closest_hits_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts,
                                    std::span<RayStats> stats) const {
  if (stats.empty()) {
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = closest_hit(rays[i], opts);
  } else {
    for (std::size_t i = 0; i < rays.size(); ++i) hits[i] = closest_hit(rays[i], opts, &stats[i]);
  }
}

void Accelerator::closest_hits_packets(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts) const {
  if (hits.size() != rays.size())
    throw std::invalid_argument("closest_hits_packets: " + name() + ": the hit span differs in size from the ray span");
  closest_packets_span(rays, hits, opts);
}

void Accelerator::any_hits_packets(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                                   const QueryOptions& opts) const {
  if (occluded.size() != rays.size())
    throw std::invalid_argument("any_hits_packets: " + name() +
                                ": the occluded span differs in size from the ray span");
  any_packets_span(rays, occluded, opts);
}

void Accelerator::closest_packets_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& opts) const {
  closest_hits_span(rays, hits, opts, {});  // per ray, counter-free
}

void Accelerator::any_packets_span(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                                   const QueryOptions& opts) const {
  for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = any_hit(rays[i], opts) ? 1 : 0;
}

RayRefusals ray_refusals(const Accelerator& accel, std::span<const Ray> rays) {
  RayRefusals r;
  r.refused.assign(rays.size(), 0);
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (std::string why = accel.ray_problem(rays[i]); !why.empty()) {
      r.refused[i] = 1;
      if (r.count++ == 0) {
        r.first = i;
        r.reason = std::move(why);
      }
    }
  return r;
}

std::string without_name_prefix(std::string message, std::string_view name) {
  if (message.starts_with(name) && message.compare(name.size(), 2, ": ") == 0) message.erase(0, name.size() + 2);
  return message;
}

}  // namespace accelviz
