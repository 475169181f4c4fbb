// accelviz animate SCENE --frames N: plays the scene's motion on the
// two-level structure and prints per-frame stats (what moved, TLAS rebuild,
// BLAS refit and rebuild times, SAH of the refitted vs a fresh BLAS, and
// the instance overlap of the frame's instance boxes).
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "app/cli_common.h"
#include "core/accel/tlas/tlas.h"
#include "core/accel/tlas/tlas_overlap.h"
#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "core/util/parallel.h"

namespace accelviz::cli {

nlohmann::json frame_stats_json(const FrameStats& f) {
  return {{"frame", f.frame},
          {"time", f.time},
          {"moved_instances", f.moved_instances},
          {"refits", f.refits},
          {"rebuilds", f.rebuilds},
          {"tlas_rebuilt", f.tlas_rebuilt},
          {"tlas_rebuild_ms", f.tlas_rebuild_ms},
          {"refit_ms", f.refit_ms},
          {"rebuild_ms", f.rebuild_ms},
          {"sah_refit", f.sah_refit},
          {"sah_rebuilt", f.sah_rebuilt},
          {"overlap_area", f.overlap.area_ratio},
          {"overlap_volume", f.overlap.volume_ratio},
          {"overlap_pairs", f.overlap.overlapping_pairs}};
}

namespace {

struct AnimateOptions {
  std::string scene;
  int frames = 10;
  double dt = 1.0 / 25.0;
  double rebuild_ratio = 1.3;
  unsigned threads = 0;
  bool json = false;
};

int run_animate(const AnimateOptions& o, const GlobalOptions& global) {
  if (!(o.dt > 0.0) || !std::isfinite(o.dt))
    throw UsageError("--dt: must be a finite number > 0 seconds, got " + std::to_string(o.dt));
  // refit's rule: rebuild when refit SAH / fresh SAH exceeds R, so R = 1 (rebuild on any decay) is one.
  if (o.rebuild_ratio != 0.0 && !(o.rebuild_ratio >= 1.0 && std::isfinite(o.rebuild_ratio))) {
    char got[32];
    std::snprintf(got, sizeof got, "%g", o.rebuild_ratio);
    throw UsageError(std::string("--rebuild-ratio: must be a finite number >= 1 (or 0: always refit), got ") + got);
  }
  Progress progress(global.quiet);
  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  progress.end(count_of(scene.instances.size(), "instance"));
  const SceneEffects fx = decide_effects(scene);
  if (!fx.per_frame_updates.on) {
    std::fprintf(stderr, "accelviz: %s: %s; each frame costs nothing\n", o.scene.c_str(),
                 fx.per_frame_updates.reason.c_str());
  }
  progress.begin("building tlas");
  TlasOptions to;
  to.blas.threads = o.threads;
  to.blas.compute_epo = false;
  to.tlas = to.blas;
  Tlas tlas(scene, to, progress.callback());
  progress.end(std::to_string(static_cast<long long>(tlas.build_stats().build_ms)) + " ms");
  AnimatorOptions ao;
  ao.rebuild_ratio = o.rebuild_ratio;
  SceneAnimator animator(scene, tlas, ao);
  if (o.json) {
    // What the table's heading line says, and the build: the lines after it are the frames.
    print_json_line({{"scene", o.scene},
                     {"instances", tlas.instances().size()},
                     {"blas", tlas.blas_count()},
                     {"memory_two_level", tlas.memory_two_level()},
                     {"memory_flattened_estimate", tlas.memory_flattened_estimate()},
                     {"build_ms", tlas.build_stats().build_ms},
                     {"threads", resolve_threads(o.threads)},
                     {"animates", fx.per_frame_updates.on},
                     {"frames", o.frames},
                     {"dt", o.dt},
                     {"rebuild_ratio", o.rebuild_ratio},
                     {"program", program_json()}});
  } else {
    std::printf("%s: %s, %zu BLAS, two-level %.1f MiB (flattened estimate %.1f MiB), build %.1f ms\n", o.scene.c_str(),
                count_of(tlas.instances().size(), "instance").c_str(), tlas.blas_count(),
                static_cast<double>(tlas.memory_two_level()) / 1048576.0,
                static_cast<double>(tlas.memory_flattened_estimate()) / 1048576.0, tlas.build_stats().build_ms);
    std::printf("%5s %8s %7s %6s %8s %9s %9s %10s %10s %10s %9s\n", "frame", "time", "moved", "refits", "rebuilds",
                "tlas_ms", "refit_ms", "rebuild_ms", "sah_refit", "sah_fresh", "overlap");
  }
  // Nothing moves: no frame is stepped, but each row still says its time and
  // the (unchanging) overlap of the instance boxes.
  FrameStats still;
  if (!fx.per_frame_updates.on) still.overlap = instance_overlap(tlas);
  for (int f = 0; f < o.frames; ++f) {
    FrameStats s = still;
    if (fx.per_frame_updates.on) {
      try {
        s = animator.step(static_cast<float>(f * o.dt));
      } catch (const std::invalid_argument& e) {
        // Which file and which moment: "tlas: instance 3: ..." alone named neither.
        // The advice to take a single-level structure is for the views that can; animate cannot.
        std::string what = e.what();
        if (const std::size_t cut = what.find("; the single-level structures"); cut != std::string::npos)
          what = what.substr(0, cut) + " (animate plays the two-level structure only)";
        char when[64];
        std::snprintf(when, sizeof when, "frame %d (t = %g s): ", f, f * o.dt);
        throw std::runtime_error(o.scene + ": " + when + what);
      }
    } else {
      s.frame = static_cast<std::uint32_t>(f);
      s.time = static_cast<float>(f * o.dt);
    }
    if (o.json) {
      print_json_line(frame_stats_json(s));
    } else {
      std::printf("%5d %8.3f %7u %6u %8u %9.2f %9.2f %10.2f %10.2f %10.2f %9.4f\n", f, static_cast<double>(s.time),
                  s.moved_instances, s.refits, s.rebuilds, s.tlas_rebuild_ms, s.refit_ms, s.rebuild_ms, s.sah_refit,
                  s.sah_rebuilt, s.overlap.area_ratio);
    }
  }
  return 0;
}

Command add_animate_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<AnimateOptions>();
  CLI::App* sub = parent.add_subcommand(
      "animate", "Play a scene's motion on the two-level structure: per-frame TLAS rebuild, BLAS refit/rebuild, SAH");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--frames", o->frames, "Frames to play")->check(CLI::Range(1, 100000))->capture_default_str();
  // At most 1e4 s: 3e38 overflowed the frames' times (a transform of inf), 1e30 lost every step to
  // float's rounding (nothing moved).
  sub->add_option("--dt", o->dt, "Seconds between frames")->check(finite_range(1e-6, 1e4))->capture_default_str();
  sub->add_option("--rebuild-ratio", o->rebuild_ratio,
                  "Rebuild a deforming BLAS when refit SAH / fresh SAH exceeds this (0: always refit)")
      ->capture_default_str();
  add_threads_option(sub, o->threads, "Build threads (0: all)");
  sub->add_flag("--json", o->json, "One JSON object per frame instead of the table");
  return {sub, [o, &global] { return run_animate(*o, global); }};
}

const CommandRegistration register_animate{add_animate_command};

}  // namespace

}  // namespace accelviz::cli
