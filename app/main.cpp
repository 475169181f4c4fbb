// accelviz: entry point. Parses the command line and dispatches to one
// subcommand per cmd_*.cpp, or, without a subcommand, opens the window
// (app/gui/) on a scene, or runs a script in it; with no display it renders
// the demo heatmap headless instead. Every failure ends here as one line on
// stderr: exit 1 for a runtime problem (bad file, failed build, failed
// script), 2 for a usage error.
#include "app/cli_common.h"
#include "core/scene/load.h"
#include "core/util/one_line.h"
#ifdef ACCELVIZ_HAVE_UI
#include "app/gui/gui.h"
#endif

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

/// Whether a lone argument names a scene rather than a mistyped subcommand:
/// a built-in spec, a scene file extension, or a file that exists.
bool looks_like_scene(const std::string& arg) {
  if (arg.rfind("builtin:", 0) == 0) return true;
  std::string ext = std::filesystem::path(arg).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".gltf" || ext == ".glb" || ext == ".obj") return true;
  std::error_code ec;
  return std::filesystem::is_regular_file(arg, ec);
}

std::string builtin_list() {
  std::string s = "Built-in scenes (SCENE = builtin:NAME[?key=value&...]):\n";
  for (const accelviz::BuiltinSceneInfo& b : accelviz::builtin_scenes())
    s += "  " + b.name + ": " + b.description + (b.parameters.empty() ? "" : " [" + b.parameters + "]") + "\n";
  return s;
}

}  // namespace

namespace {

int run(int argc, char** argv) {
  using namespace accelviz;
  CLI::App app{
      "accelviz: a lab for ray-tracing acceleration structures.\n"
      "Without a subcommand it opens the interactive window on SCENE (default: the demo scene); without a\n"
      "display it renders the demo scene's heatmap to a PNG in the current directory instead."};
  app.set_version_flag("--version", cli::version_line());
  app.require_subcommand(0, 1);
  app.footer("\nSCENE is a .gltf/.glb/.obj file or builtin:NAME[?key=value&...].\n" + builtin_list() +
             "Exit codes: 0 success, 1 error (bad file, failed build...), 2 usage error.\n"
             "Documentation: docs/cli.md");

  cli::GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "No progress messages on stderr");
  std::string scene_arg, script_arg;
  bool no_settings = false;
  app.add_option("SCENE", scene_arg, "Scene to open in the window (.gltf, .glb, .obj or builtin:NAME[?...])");
  app.add_option("--script", script_arg,
                 "Run the commands in FILE in the window, then quit (implies --no-settings; see docs/gui.md)")
      ->option_text("FILE");
  app.add_flag("--no-settings", no_settings,
               "Neither read nor write settings or window layout (also: ACCELVIZ_NO_SETTINGS=1)");

  std::vector<cli::Command> commands = {
      cli::add_info_command(app, global),  cli::add_render_command(app, global), cli::add_bench_command(app, global),
      cli::add_trace_command(app, global), cli::add_rays_command(app, global),
  };
  for (cli::CommandFactory factory : cli::registered_commands()) commands.push_back(factory(app, global));

  // Whole numbers in decimal only: CLI11 reads "010" as octal (8 buckets, -j 010 as 8 threads),
  // "0x10" as hex, and "-1" for an unsigned option as 2^64 - 1 (a seed). Checked on every INT and
  // UINT option of every command, before the option's own range check (a transform runs first), so
  // that "abc" and "09" are answered as not decimal rather than out of range.
  const std::function<void(CLI::App*)> decimal_only = [&](CLI::App* a) {
    for (CLI::Option* opt : a->get_options()) {
      const std::string type = opt->get_type_name();
      const bool is_unsigned = type.rfind("UINT", 0) == 0, is_signed = type.rfind("INT", 0) == 0;
      if (!is_unsigned && !is_signed) continue;
      opt->transform(CLI::Validator(
          [is_unsigned](std::string& text) -> std::string {
            const std::size_t digits = !is_unsigned && text.size() > 1 && text[0] == '-' ? 1 : 0;
            bool ok = text.size() > digits;
            for (std::size_t i = digits; ok && i < text.size(); ++i) ok = text[i] >= '0' && text[i] <= '9';
            if (ok && text[digits] == '0' && text.size() > digits + 1) ok = false;  // octal in CLI11
            if (!ok)
              return std::string("expected a whole number in decimal digits (") + (is_unsigned ? "no sign, " : "") +
                     "no leading zero), got '" + text + "'";
            // CLI11 clamps a value beyond 64 bits to the largest (a --seed of 10^23 ran as 2^64 - 1).
            std::uint64_t u = 0;
            std::int64_t s = 0;
            const char* end = text.data() + text.size();
            const bool fits = is_unsigned ? std::from_chars(text.data(), end, u).ec == std::errc()
                                          : std::from_chars(text.data(), end, s).ec == std::errc();
            if (!fits) return "'" + text + "' is beyond a 64-bit whole number";
            return {};
          },
          ""));
    }
    for (CLI::App* sub : a->get_subcommands({})) decimal_only(sub);
  };
  decimal_only(&app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every real parse error is a usage error (2). Their text goes
    // through write_stdout, which keeps a failed write's reason (CLI11's own std::endl flush would
    // fail first, glibc drop the buffer, and main's last flush succeed with no reason to tell).
    std::ostringstream out;
    const int code = app.exit(e, out, std::cerr);
    cli::write_stdout(out.str());
    return code == 0 ? 0 : 2;
  }

  try {
    // An option given an empty value (`--camera ""`: a variable that was not set) is a usage error,
    // not the option's default taken in silence.
    for (const cli::Command& c : commands) {
      if (!c.app->parsed()) continue;
      for (const CLI::Option* opt : c.app->get_options())
        if (opt->count() > 0 && opt->get_items_expected_min() > 0)
          for (const std::string& value : opt->results())
            if (value.empty())
              throw cli::UsageError(opt->get_name() + ": an empty value" +
                                    (opt->get_required() || opt->get_positional()
                                         ? std::string(" (it needs one)")
                                         : std::string(" (leave the option out for its default)")));
    }
    // ACCELVIZ_PARSE_ONLY=1: the command line is read and checked as above, then nothing runs
    // (tests/cli/docs_commands.sh checks every command the documentation prints this way).
    const char* parse_only_env = std::getenv("ACCELVIZ_PARSE_ONLY");
    const bool parse_only = parse_only_env && std::string(parse_only_env) == "1";
    const auto parsed_only = [] {
      std::fprintf(stderr, "accelviz: ACCELVIZ_PARSE_ONLY=1: the command line parses; nothing was run\n");
      return 0;
    };
    for (const cli::Command& c : commands)
      if (c.app->parsed()) return parse_only ? parsed_only() : c.run();
    if (!scene_arg.empty() && !looks_like_scene(scene_arg)) {
      std::string names;
      for (const cli::Command& c : commands) names += (names.empty() ? "" : ", ") + c.app->get_name();
      throw cli::UsageError("'" + scene_arg + "' is neither a subcommand (" + names +
                            ") nor a scene (.gltf/.glb/.obj file or builtin:NAME)");
    }
    if (parse_only) return parsed_only();
    const bool want_window = !scene_arg.empty() || !script_arg.empty();
#ifdef ACCELVIZ_HAVE_UI
    if (display_available()) {
      GuiOptions g;
      if (!scene_arg.empty()) g.scene = scene_arg;
      if (!script_arg.empty()) g.script = script_arg;
      g.use_settings = !no_settings;
      g.quiet = global.quiet;
      try {
        return run_gui(g);
      } catch (const NoWindow& e) {
        if (want_window) throw std::runtime_error(std::string("cannot open a window: ") + e.what());
        if (!global.quiet) std::fprintf(stderr, "accelviz: cannot open a window (%s)\n", joined_line(e.what()).c_str());
      }
    } else if (want_window) {
      throw std::runtime_error(
          "no display (DISPLAY and WAYLAND_DISPLAY are unset): the window needs one; `accelviz render` draws "
          "pictures without a window");
    }
#else
    if (want_window) throw std::runtime_error("this build has no window (configure with ACCELVIZ_BUILD_UI=ON)");
#endif
    return cli::run_demo(global);
  } catch (const cli::UsageError& e) {
    std::fprintf(stderr, "accelviz: %s\n", joined_line(e.what()).c_str());
    return 2;
  } catch (const BuildCancelled&) {
    std::fprintf(stderr, "accelviz: cancelled\n");
    return 1;
  } catch (const std::bad_alloc&) {
    // Which file and options asked for it: the command line, cut to one line.
    std::string args;
    for (int i = 1; i < argc; ++i) args += (i > 1 ? " " : "") + std::string(argv[i]);
    if (args.size() > 200) args = args.substr(0, 197) + "...";
    std::fprintf(stderr, "accelviz: out of memory running '%s' (a smaller scene, size or ray count needs less)\n",
                 joined_line(args).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accelviz: %s\n", joined_line(e.what()).c_str());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Past the file-size limit (ulimit -f) a write fails with EFBIG instead of
  // the signal killing the process: the write's error is reported and the
  // output's temporary file removed, as for a full disk.
  std::signal(SIGXFSZ, SIG_IGN);
  // Into a file or pipe, stdout keeps up to 1 MiB before writing: a write that fails then fails in a
  // flush, whose reason is kept (flush_stdout, below). With glibc's 4 KiB buffer a table or JSON
  // longer than that failed inside `<<`, and the reason (a full disk) was lost.
  if (!isatty(STDOUT_FILENO)) std::setvbuf(stdout, nullptr, _IOFBF, std::size_t{1} << 20);
  const int code = run(argc, argv);
  // What went to stdout (tables, JSON) must have arrived: `bench --json >
  // full-disk/results.json` said nothing and exited 0 with the file cut short.
  // An earlier failed flush (a JSON line) dropped its buffer: its reason was kept.
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  if (!flushed || std::ferror(stdout)) {
    const int err = accelviz::cli::stdout_flush_errno() ? accelviz::cli::stdout_flush_errno() : errno;
    std::fprintf(stderr, "accelviz: stdout: write failed%s%s\n", err ? ": " : "", err ? std::strerror(err) : "");
    return code == 0 ? 1 : code;
  }
  return code;
}
