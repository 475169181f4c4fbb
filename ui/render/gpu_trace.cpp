#include "ui/render/gpu_trace.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/query/camera.h"
#include "core/util/parallel.h"
#include "core/util/timing.h"

namespace accelviz {
namespace {

static_assert(sizeof(Triangle) == 36, "the shader reads triangles as 9 packed floats");

constexpr int kGroup = 8;  // local_size_x/y of trace_bvh.comp

/// A storage buffer with `bytes` of `data` (at least 4 bytes: GL rejects empty stores).
GlObject make_storage(const void* data, std::size_t bytes, const char* what) {
  GLint64 limit = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &limit);
  if (limit > 0 && static_cast<GLint64>(bytes) > limit)
    throw GlError(std::string("GPU trace: ") + what + " need " + std::to_string(bytes) +
                  " bytes, more than this GL's storage-block limit of " + std::to_string(limit));
  GlObject buf = GlObject::create(GlObject::Kind::buffer);
  const std::uint32_t zero = 0;
  glNamedBufferStorage(buf.id(), static_cast<GLsizeiptr>(bytes > 0 ? bytes : sizeof zero), bytes > 0 ? data : &zero, 0);
  return buf;
}

}  // namespace

bool gpu_pixel_matches(const GpuTraceResult& gpu, std::size_t i, const RayStats& stats, const Hit& hit) {
  const RayStats& g = gpu.stats[i];
  return stats.nodes_visited == g.nodes_visited && stats.box_tests == g.box_tests && stats.prim_tests == g.prim_tests &&
         stats.nodes_culled == g.nodes_culled && stats.nodes_missed == g.nodes_missed && hit.prim == gpu.hits[i].prim &&
         std::bit_cast<std::uint32_t>(hit.t) == std::bit_cast<std::uint32_t>(gpu.hits[i].t);
}

std::string gpu_trace_unsupported(const std::string& structure_name) {
  if (structure_name != "bvh") return "only the bvh structure is traced on the GPU";
  return {};
}

GpuBvhTracer::GpuBvhTracer() : program_(ShaderProgram::build({"trace_bvh.comp"})) {
  check_gl_errors("GPU trace setup");
}

void GpuBvhTracer::upload(const Bvh& bvh) {
  const std::span<const BvhNode> nodes = bvh.nodes();
  const std::vector<Triangle> tris = bvh.copy_leaf_triangles();
  nodes_ = make_storage(nodes.data(), nodes.size_bytes(), "the BVH nodes");
  tris_ = make_storage(tris.data(), tris.size() * sizeof(Triangle), "the triangles");
  node_count_ = nodes.size();
  prim_ids_.assign(bvh.prim_indices().begin(), bvh.prim_indices().end());
  normals_.resize(tris.size());
  for (std::size_t k = 0; k < tris.size(); ++k) normals_[k] = triangle_normal(tris[k]);
  uploaded_ = true;
  check_gl_errors("GPU trace upload");
}

GpuTraceResult GpuBvhTracer::trace(const Camera& camera, int width, int height, const QueryOptions& query) {
  GpuTraceResult r;
  trace(camera, width, height, query, r);
  return r;
}

void GpuBvhTracer::trace(const Camera& camera, int width, int height, const QueryOptions& query, GpuTraceResult& into) {
  begin(camera, width, height, query);
  trace_rows(height);
  result(into);
}

void GpuBvhTracer::begin(const Camera& camera, int width, int height, const QueryOptions& query) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("GPU trace: image size must be positive");
  if (!uploaded_) throw std::logic_error("GPU trace: no BVH uploaded");
  width_ = height_ = rows_done_ = 0;
  band_ms_ = 0.0;
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const std::size_t bytes = n * sizeof(GpuPixel);
  if (!out_ || out_bytes_ < bytes) {
    // The shader writes `out_`, which is never mapped, so the driver can keep
    // it in the GPU's own memory; result() copies it into `readback_`, a
    // buffer in client memory made for reading. (Mapping `out_` itself made
    // NVIDIA's driver move it: on an H200 the traces after the first took
    // 7.5 ms instead of 3.5, docs/performance.md "GPU path".)
    out_ = GlObject::create(GlObject::Kind::buffer);
    glNamedBufferStorage(out_.id(), static_cast<GLsizeiptr>(bytes), nullptr, 0);
    readback_ = GlObject::create(GlObject::Kind::buffer);
    glNamedBufferStorage(readback_.id(), static_cast<GLsizeiptr>(bytes), nullptr,
                         GL_MAP_READ_BIT | GL_CLIENT_STORAGE_BIT);
    out_bytes_ = bytes;
  }
  // Rows not traced yet hold an earlier image: read_pixels marks them
  // untraced when it reads them (a whole trace never clears anything).

  // The per-camera constants of core's camera_ray, computed by the same C++.
  const float aspect = camera_aspect(camera, width, height);
  const float tan_half = std::tan(0.5f * camera.yfov);
  const glm::vec3 right = glm::cross(camera.forward, camera.up);
  program_.set("u_width", width);
  program_.set("u_height", height);
  glProgramUniform1ui(program_.id(), glGetUniformLocation(program_.id(), "u_node_count"),
                      static_cast<GLuint>(node_count_));
  program_.set("u_position", camera.position);
  program_.set("u_forward", camera.forward);
  program_.set("u_up", camera.up);
  program_.set("u_right", right);
  program_.set("u_tan_half", tan_half);
  program_.set("u_aspect", aspect);
  program_.set("u_slab_scale", kSlabExitScale);
  program_.set("u_ordered", query.ordered ? 1 : 0);
  program_.set("u_back_to_front", query.back_to_front ? 1 : 0);
  program_.set("u_xray", query.xray ? 1 : 0);
  program_.set("u_watertight", query.triangle_test == TriangleTest::watertight ? 1 : 0);
  check_gl_errors("GPU trace setup");
  width_ = width;
  height_ = height;
}

double GpuBvhTracer::trace_rows(int rows) {
  if (height_ <= 0) throw std::logic_error("GPU trace: trace_rows before begin");
  if (rows < 1) throw std::invalid_argument("GPU trace: a band needs at least one row");
  const int y0 = rows_done_;
  const int y1 = std::min(height_, y0 + std::min(rows, height_));
  if (y0 >= y1) return 0.0;
  program_.set("u_row0", y0);
  program_.set("u_row_end", y1);
  program_.use();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, nodes_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, tris_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, out_.id());
  glFinish();  // nothing queued before counts against the band
  const auto t0 = std::chrono::steady_clock::now();
  glDispatchCompute(static_cast<GLuint>((width_ + kGroup - 1) / kGroup),
                    static_cast<GLuint>((y1 - y0 + kGroup - 1) / kGroup), 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_CLIENT_MAPPED_BUFFER_BARRIER_BIT);
  glFinish();
  const double ms = ms_since(t0);
  for (GLuint b = 0; b < 3; ++b) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, b, 0);
  glUseProgram(0);
  check_gl_errors("GPU trace dispatch");
  rows_done_ = y1;
  band_ms_ += ms;
  return ms;
}

GpuTraceResult GpuBvhTracer::result() const {
  GpuTraceResult r;
  result(r);
  return r;
}

void GpuBvhTracer::result(GpuTraceResult& r) const {
  if (height_ <= 0) throw std::logic_error("GPU trace: result before begin");
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  r.width = width_;
  r.height = height_;
  r.trace_ms = band_ms_;
  const auto t1 = std::chrono::steady_clock::now();
  r.stats.resize(n);
  r.hits.resize(n);
  read_pixels([&](std::span<const GpuPixel> px) {
    parallel_for(n, 0, 16384, [&](std::size_t i0, std::size_t i1, unsigned) {
      for (std::size_t i = i0; i < i1; ++i) {
        r.stats[i] = stats_of(px[i]);  // every field: the storage may hold an earlier trace
        r.hits[i] = hit_of(px[i]);
      }
    });
  });
  r.readback_ms = ms_since(t1);
}

double GpuBvhTracer::read_pixels(const std::function<void(std::span<const GpuPixel>)>& use) const {
  if (height_ <= 0) throw std::logic_error("GPU trace: read before begin");
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  const auto t0 = std::chrono::steady_clock::now();
  // Copied on the GPU into the client-memory buffer, read from its mapping
  // (no copy on the CPU).
  const auto bytes = static_cast<GLsizeiptr>(n * sizeof(GpuPixel));
  if (rows_done_ < height_) {
    // Rows no band has traced: untraced (all bits set: counters kUntraced,
    // prim kInvalidId, t a NaN).
    const std::size_t row_bytes = static_cast<std::size_t>(width_) * sizeof(GpuPixel);
    const std::uint32_t untraced = kUntraced;
    glClearNamedBufferSubData(out_.id(), GL_R32UI, static_cast<GLintptr>(rows_done_ * row_bytes),
                              static_cast<GLsizeiptr>((height_ - rows_done_) * row_bytes), GL_RED_INTEGER,
                              GL_UNSIGNED_INT, &untraced);
  }
  glCopyNamedBufferSubData(out_.id(), readback_.id(), 0, 0, bytes);
  const auto* px = static_cast<const GpuPixel*>(glMapNamedBufferRange(readback_.id(), 0, bytes, GL_MAP_READ_BIT));
  if (px == nullptr) {
    check_gl_errors("GPU trace readback");
    throw GlError("GPU trace readback: the output buffer could not be mapped");
  }
  const double ms = ms_since(t0);
  {
    struct Unmap {  // also when `use` throws (a thread that cannot start)
      GLuint id;
      ~Unmap() { glUnmapNamedBuffer(id); }
    } unmap{readback_.id()};
    use(std::span<const GpuPixel>(px, n));
  }
  check_gl_errors("GPU trace readback");
  return ms;
}

RayStats GpuBvhTracer::stats_of(const GpuPixel& p) {
  RayStats s;
  s.nodes_visited = p.nodes_visited;
  s.box_tests = p.box_tests;
  s.prim_tests = p.prim_tests;
  s.nodes_culled = p.nodes_culled;
  s.nodes_missed = p.nodes_missed;
  return s;
}

Hit GpuBvhTracer::hit_of(const GpuPixel& p) const {
  Hit h;
  if (is_hit(p)) {
    h.prim = prim_ids_[p.prim];  // as Bvh::closest_hit maps its leaf-order hit
    h.ng = normals_[p.prim];
    h.t = p.t;
  }
  return h;
}

double gpu_metric_image(const GpuBvhTracer& tracer, const Camera& camera, const HeatmapOptions& opts,
                        HeatmapFigures* figures, MetricImage& into, const GpuBlockVisit& visit) {
  if (tracer.rows_total() != opts.height || tracer.width() != opts.width)
    throw std::invalid_argument("heatmap: the GPU trace is " + std::to_string(tracer.width()) + "x" +
                                std::to_string(tracer.rows_total()) + ", the options ask for " +
                                std::to_string(opts.width) + "x" + std::to_string(opts.height));
  const std::size_t n = static_cast<std::size_t>(opts.width) * static_cast<std::size_t>(opts.height);
  const bool shaded = opts.metric == HeatMetric::shaded;  // the one metric that reads the ray
  const bool reads_hit = shaded || opts.metric == HeatMetric::depth;
  const Ray no_ray;
  const Hit no_hit;
  const auto w = static_cast<std::size_t>(opts.width);
  bool done = false;
  const double ms = tracer.read_pixels([&](std::span<const GpuPixel> px) {
    done = metric_image_by_blocks(
        n, opts, tracer.trace_ms(), figures,
        [&](std::size_t i0, std::size_t i1, float* values) {
          std::uint64_t hit_count = 0;
          for (std::size_t i = i0; i < i1; ++i) {
            const Hit hit = reads_hit ? tracer.hit_of(px[i]) : no_hit;
            const Ray ray =
                shaded ? primary_ray(camera, static_cast<int>(i % w), static_cast<int>(i / w), opts.width, opts.height)
                       : no_ray;
            values[i - i0] =
                metric_value(opts.metric, ray, hit, GpuBvhTracer::stats_of(px[i]), opts.c_trav, opts.c_isect);
            if (tracer.is_hit(px[i])) ++hit_count;
          }
          if (visit) visit(i0, px.subspan(i0, i1 - i0), std::span<const float>(values, i1 - i0));
          return hit_count;
        },
        into);
  });
  if (!done) throw BuildCancelled();
  return ms;
}

MetricImage gpu_render_metric(GpuBvhTracer& tracer, const Camera& camera, const HeatmapOptions& opts,
                              HeatmapFigures* figures, double* readback_ms) {
  if (opts.width <= 0 || opts.height <= 0) throw std::invalid_argument("heatmap: image size must be positive");
  tracer.begin(camera, opts.width, opts.height, opts.query);
  tracer.trace_rows(opts.height);
  MetricImage img;
  const double ms = gpu_metric_image(tracer, camera, opts, figures, img);
  if (readback_ms) *readback_ms = ms;
  return img;
}

}  // namespace accelviz
