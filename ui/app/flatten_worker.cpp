#include "ui/app/flatten_worker.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "core/accel/tlas/flatten_json.h"
#include "core/util/one_line.h"
#include "core/util/timing.h"

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

}  // namespace

namespace {

struct IdRange {
  std::uint32_t lo = 0, hi = 0;
  bool all = false;
  std::string text;
};

/// The items of an id list, checked for syntax only.
std::vector<IdRange> parse_id_ranges(std::string_view text) {
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

std::string flattened_spec(const std::string& spec, std::size_t merged) {
  return spec + " [flattened " + count_of(merged, "instance") + "]";
}

nlohmann::json flatten_result_json(const FlattenResult& r, const std::string& spec) {
  nlohmann::json j = {{"scene", spec},
                      {"instances", format_instance_ids(r.instances)},
                      {"width", r.width},
                      {"height", r.height},
                      {"ms", r.ms}};
  if (!r.error.empty()) j["error"] = r.error;
  if (r.figures) {
    j.update(flatten_what_if_json(*r.figures));
  }
  if (r.committed) j["committed"] = r.committed->spec;
  return j;
}

FlattenResult run_flatten_request(const FlattenRequest& r, const std::function<bool()>& keep_going,
                                  const std::function<void(double)>& fraction) {
  const auto t0 = std::chrono::steady_clock::now();
  FlattenResult out;
  out.kind = r.kind;
  out.scene = r.scene.get();
  out.instances = r.instances;
  out.width = r.width;
  out.height = r.height;
  if (!r.scene) throw std::invalid_argument("flatten: no scene");
  if (r.instances.empty()) throw std::invalid_argument("flatten: no instances selected");
  if (r.kind == FlattenRequest::Kind::preview) {
    out.figures = flatten_what_if(r.scene->scene, r.instances, r.camera, r.width, r.height, r.options, [&](double f) {
      if (fraction) fraction(f);
      return keep_going();
    });
  } else {
    if (!keep_going()) throw BuildCancelled();
    auto loaded = std::make_shared<LoadedScene>();
    FlattenedScene flat = flatten_instances(r.scene->scene, r.instances);
    if (!keep_going()) throw BuildCancelled();
    loaded->scene = std::move(flat.scene);
    loaded->spec = flattened_spec(r.scene->spec, r.instances.size());
    loaded->in_memory = true;
    if (fraction) fraction(1.0);
    out.committed = std::move(loaded);
  }
  out.ms = ms_since(t0);
  return out;
}

FlattenWorker::FlattenWorker()
    : worker_([this](const FlattenRequest& r, std::uint64_t id, const std::function<bool()>& keep_going,
                     const std::function<void(std::shared_ptr<const FlattenResult>)>& publish) {
        fraction_ = 0.0;
        auto result = std::make_shared<FlattenResult>();
        try {
          *result = run_flatten_request(r, keep_going, [this](double f) { fraction_ = f; });
        } catch (const BuildCancelled&) {
          return;  // superseded or cancelled: nothing to show
        } catch (const std::exception& e) {
          result->kind = r.kind;
          result->scene = r.scene.get();
          result->instances = r.instances;
          result->error = e.what();
        }
        result->id = id;
        publish(std::move(result));
      }) {}

}  // namespace accelviz
